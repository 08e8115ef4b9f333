"""Row fields: a component's numbers kept in one array per field over a crowd, read and written as before.

A crowd's systems update a few numbers of every puppet each step (a heading, a time in
state, a spring's velocity). On plain objects each such update is Python work per puppet
— a pass that touches a thousand objects, cold in the cache after the other stages — and a
column of :mod:`engine.columns` still has to check, puppet by puppet, that no code
replaced its field since. A *row field* removes both: the component class declares the
field row-backed (:func:`keep_in_rows`), and once a batch of components is linked to a
:class:`RowBlock` (:meth:`RowStore.block`) the field's value lives in the block's array,
row ``i`` for component ``i``. Reading ``c.field`` returns it (a Python ``float`` or
``int``, or a read-only copy of the row for an array field), assigning ``c.field = v``
writes it into the row: no field can be replaced behind the block's back, so a system
reads and writes the whole array with no check and no Python per puppet.

An array field keeps a plain field's value semantics. A plain field holds one array
object that code replaces by assignment (every system of the brain stage assigns new
arrays, none mutates one in place), so what a reader got keeps its values whatever is
assigned later: ``old = c.lead; c.lead = new; c.lead = old`` restores the old values, and
an array read before a step still holds the values it had then. A view of the row would
break both (it shows whatever the row holds now, and a system writes the rows in place),
so a read hands out a copy; the copy is read-only, because an in-place change of it
(``c.lead[0] = x``) — which on a plain field changes the field — would otherwise be lost
without a word: it raises instead. ``copy``, ``deepcopy`` and ``pickle`` see a plain
object (:func:`_plain_state`).

What a reader sees is what it saw before, to the type: a value the block cannot hold
exactly (an ``int`` in a float field, an ``np.float64``, an array of another shape or
type) *unlinks* that component (its values go back into the object, the block is marked
stale, and the next :meth:`RowStore.block` links the batch anew) — so the state hash
(:mod:`engine.hashing`, which hashes a Python ``float`` and an ``np.float64`` differently)
is bit for bit what it was with plain fields.

Before it is linked (just spawned, or alone in a test) a component keeps its values in
its own ``__dict__``, as a plain dataclass does.
"""

from __future__ import annotations

import operator
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.ecs import World

__all__ = ["RowBlock", "RowStore", "keep_in_rows", "row_store"]

_LINK = "_row_link"
"""The instance attribute holding ``(block, row)`` of a linked component."""


class RowBlock:
    """The arrays of one linked batch: ``arrays[name]`` ``[N, ...]`` and ``present[name]`` for a field that may be
    ``None``."""

    __slots__ = ("arrays", "present", "stale", "failed", "objects_set", "memo")

    def __init__(self) -> None:
        self.arrays: dict[str, NDArray[Any]] = {}
        self.present: dict[str, NDArray[np.bool_]] = {}
        self.stale = False
        self.failed = False
        """Linking failed (a value it cannot hold exactly): the batch stays plain objects until it changes."""
        self.objects_set = 0
        """How many times an ``"object"`` field was assigned: what a system derived from those objects
        (kept in ``memo``) holds while it is unchanged."""
        self.memo: dict[str, Any] = {}


class _RowField:
    """Data descriptor of one row-backed field (see the module docstring)."""

    __slots__ = ("name", "kind", "shape", "optional")

    def __init__(self, name: str, kind: str, shape: tuple[int, ...], optional: bool) -> None:
        self.name, self.kind, self.shape, self.optional = name, kind, shape, optional

    def __get__(self, obj: Any, objtype: type | None = None) -> Any:
        if obj is None:
            return self
        d = obj.__dict__
        link = d.get(_LINK)
        if link is None:
            return d[self.name]
        block, row = link
        name = self.name
        if self.optional and not block.present[name][row]:
            return None
        if self.kind == "vector":
            return _frozen(block.arrays[name][row])
        if self.kind == "object":
            return block.arrays[name][row]
        return block.arrays[name].item(row)

    def raw(self, obj: Any) -> Any:
        """The value as kept, an array field as the row itself (no copy): for reads that use it at once and keep
        nothing (linking, unlinking)."""
        link = obj.__dict__.get(_LINK)
        if link is None:
            return obj.__dict__[self.name]
        block, row = link
        name = self.name
        if self.optional and not block.present[name][row]:
            return None
        if self.kind == "vector" or self.kind == "object":
            return block.arrays[name][row]
        return block.arrays[name].item(row)

    def __set__(self, obj: Any, value: Any) -> None:
        d = obj.__dict__
        link = d.get(_LINK)
        if link is None:
            d[self.name] = value
        elif not self._store(link[0], link[1], value):
            _unlink(obj)
            d[self.name] = value

    def _store(self, block: RowBlock, row: int, value: Any) -> bool:
        """Write ``value`` into the row; ``False`` if the row cannot hold it exactly (the caller unlinks)."""
        name = self.name
        if self.kind == "object":
            block.arrays[name][row] = value
            block.objects_set += 1
            return True
        if value is None:
            if not self.optional:
                return False
            block.present[name][row] = False
            return True
        if self.kind == "float":
            if type(value) is not float:
                return False
            block.arrays[name][row] = value
        elif self.kind == "int":
            if type(value) is not int or not _INT_MIN <= value <= _INT_MAX:
                return False
            block.arrays[name][row] = value
        else:
            if type(value) is not np.ndarray or value.dtype != np.float64 or value.shape != self.shape:
                return False
            block.arrays[name][row] = value
        if self.optional:
            block.present[name][row] = True
        return True

    def column(self, values: Sequence[Any]) -> tuple[NDArray[Any], NDArray[np.bool_] | None] | None:
        """The block arrays holding ``values`` exactly (array, presence), or ``None`` if one cannot be held."""
        n = len(values)
        present = np.fromiter((v is not None for v in values), np.bool_, n) if self.optional else None
        if self.kind == "object":
            objects = np.empty(n, dtype=object)
            for i, v in enumerate(values):  # one by one: a value that is a sequence stays one object
                objects[i] = v
            return objects, None
        if self.kind == "float":
            dtype: type = np.float64
            ok = all(v is None or type(v) is float for v in values)
        elif self.kind == "int":
            dtype = np.int64
            ok = all(v is None or (type(v) is int and _INT_MIN <= v <= _INT_MAX) for v in values)
        else:
            dtype = np.float64
            ok = all(
                v is None or (type(v) is np.ndarray and v.dtype == np.float64 and v.shape == self.shape) for v in values
            )
        if not ok or (not self.optional and any(v is None for v in values)):
            return None
        out: NDArray[Any] = np.zeros((n, *self.shape), dtype=dtype)
        for i, v in enumerate(values):
            if v is not None:
                out[i] = v
        return out, present


class _Number(_RowField):
    """A float or int field that is never ``None``: the common read in fewer steps (the hash reads every one)."""

    __slots__ = ()

    def __get__(self, obj: Any, objtype: type | None = None) -> Any:
        if obj is None:
            return self
        link = obj.__dict__.get(_LINK)
        if link is None:
            return obj.__dict__[self.name]
        return link[0].arrays[self.name].item(link[1])


class _Vector(_RowField):
    """An array field that is never ``None``: a read-only copy of its row."""

    __slots__ = ()

    def __get__(self, obj: Any, objtype: type | None = None) -> Any:
        if obj is None:
            return self
        link = obj.__dict__.get(_LINK)
        if link is None:
            return obj.__dict__[self.name]
        return _frozen(link[0].arrays[self.name][link[1]])


def _frozen(row: NDArray[np.float64]) -> NDArray[np.float64]:
    """A read-only copy of a row: it keeps the values it was read with (a plain field's array is replaced, not
    changed, when the field is assigned or a system steps), and changing it in place raises instead of being lost."""
    out = row.copy()
    out.flags.writeable = False
    return out


_INT_MIN, _INT_MAX = -(2**63), 2**63 - 1


def _unlink(obj: Any) -> None:
    """Move a linked component's values back into the object and mark its block stale."""
    d = obj.__dict__
    block, _ = d[_LINK]
    d.update(_plain_values(obj))
    del d[_LINK]
    block.stale = True


def _plain_values(obj: Any) -> dict[str, Any]:
    """A linked component's row-field values as a plain object holds them (an array field as its own writable
    array, sharing no memory with the block)."""
    values = {}
    for f in _fields(type(obj)):
        value = f.raw(obj)
        values[f.name] = np.array(value) if isinstance(value, np.ndarray) else value
    return values


def _fields(cls: type) -> tuple[_RowField, ...]:
    found: tuple[_RowField, ...] = getattr(cls, "__row_fields__", ())
    return found


def keep_in_rows(cls: type, **fields: tuple[str, tuple[int, ...], bool]) -> None:
    """Declare fields of the (dataclass) component ``cls`` row-backed: ``name=(kind, shape, optional)``.

    ``kind`` is ``"float"`` (a Python float), ``"int"`` (a Python int, 64 bits), ``"vector"``
    (a float64 array of ``shape``) or ``"object"`` (any object, kept as itself; the block counts
    the assignments); ``optional`` lets a number or vector field be ``None``. Call it once, after
    the class is made: the dataclass ``__init__`` keeps assigning the fields, now through the
    descriptors."""
    made = []
    for name, (kind, shape, optional) in fields.items():
        if kind not in ("float", "int", "vector", "object"):
            raise ValueError(f"{cls.__name__}.{name}: unknown row kind {kind!r}")
        kind_of = _RowField if optional or kind == "object" else _Vector if kind == "vector" else _Number
        field = kind_of(name, kind, tuple(shape), optional)
        setattr(cls, name, field)
        made.append(field)
    cls.__row_fields__ = (*_fields(cls), *made)  # type: ignore[attr-defined]  # a class attribute added at run time
    cls.__getstate__ = _plain_state  # type: ignore[method-assign, assignment]  # object's method replaced per class
    cls.__state_columns__ = classmethod(_state_columns)  # type: ignore[attr-defined]  # added at run time


def _state_columns(cls: type, names: Sequence[str], comps: Sequence[Any]) -> list[list[Any]]:
    """The state hash's columns of ``names`` over ``comps`` (see :mod:`engine.hashing`): the values a plain read of
    each gives, to the type. Components all linked to one block are read from its arrays, a whole column at once
    (``tolist`` makes the same Python floats and ints as ``.item``; an array field's values are rows of a gathered
    copy, used at once) — one by one, the copies the attribute reads hand out would cost more than the hash."""
    if not comps or not names:
        return []
    links = [c.__dict__.get(_LINK) for c in comps]
    block = links[0][0] if links[0] is not None else None
    if block is None or any(link is None or link[0] is not block for link in links):
        return [[getattr(c, name) for c in comps] for name in names]
    rows = np.fromiter((link[1] for link in links), np.intp, len(links))
    rowed = {f.name: f for f in _fields(cls)}
    columns = []
    for name in names:
        f = rowed.get(name)
        if f is None:
            columns.append(list(map(operator.attrgetter(name), comps)))
            continue
        values = block.arrays[name][rows]
        column = list(values) if f.kind == "vector" else values.tolist()
        if f.optional:
            column = [v if p else None for v, p in zip(column, block.present[name][rows].tolist(), strict=True)]
        columns.append(column)
    return columns


def _plain_state(obj: Any) -> dict[str, Any]:
    """What ``copy.copy``, ``copy.deepcopy`` and ``pickle`` take of a component with row fields: the ``__dict__``
    of a plain (unlinked) object, its arrays copied — a copy sharing the link would write the original's row, and a
    pickle would carry the whole block."""
    d = dict(obj.__dict__)
    if d.pop(_LINK, None) is not None:
        d.update(_plain_values(obj))
    return d


class RowStore:
    """Resource: per component type, the block its current batch is linked to. Not simulation state (the values
    are the components'; the block is how they are stored)."""

    SIM_STATE = False

    def __init__(self) -> None:
        self._kept: dict[type, tuple[tuple[Any, ...], RowBlock]] = {}
        self._rows: dict[tuple[type, int], tuple[tuple[Any, ...], RowBlock, slice | NDArray[np.intp]]] = {}

    def block(self, ctype: type, owners: tuple[Any, ...]) -> RowBlock:
        """The block ``owners`` (a batch, row ``i`` for ``owners[i]``) are linked to, linking them if they are not.

        Kept while ``owners`` is the same tuple object and no component was unlinked; otherwise the
        batch is linked anew from its components' current values (Python per component, once per
        structural change). A batch holding a value no block can hold exactly gets a stale block (the
        callers use the plain objects) and is not tried again while it is the same tuple."""
        kept = self._kept.get(ctype)
        if kept is not None and kept[0] is owners and (not kept[1].stale or kept[1].failed):
            return kept[1]
        block = _link(ctype, owners)
        self._kept[ctype] = (owners, block)
        for key in [k for k in self._rows if k[0] is ctype]:  # rows into the old block: dropped with it
            del self._rows[key]
        return block

    def owners(self, ctype: type) -> tuple[Any, ...] | None:
        """The batch the type's current block holds (row ``i`` for ``owners[i]``), if there is one."""
        kept = self._kept.get(ctype)
        return None if kept is None else kept[0]

    def rows(self, ctype: type, owners: tuple[Any, ...]) -> tuple[RowBlock, slice | NDArray[np.intp]] | None:
        """Where ``owners`` (a tuple kept by the caller) are in the type's current block: every row in order
        (``slice(None)``) or their row indices; ``None`` if one of them is not in it."""
        kept = self._kept.get(ctype)
        if kept is None or kept[1].stale:
            return None
        block = kept[1]
        if owners is kept[0]:
            return block, _ALL
        known = self._rows.get((ctype, id(owners)))
        if known is not None and known[0] is owners and known[1] is block:
            return block, known[2]
        links = [o.__dict__.get(_LINK) for o in owners]
        if any(link is None or link[0] is not block for link in links):
            return None
        rows = np.array([link[1] for link in links], dtype=np.intp)
        self._rows[(ctype, id(owners))] = (owners, block, rows)
        return block, rows


_ALL = slice(None)


def _link(ctype: type, owners: tuple[Any, ...]) -> RowBlock:
    """A new block holding ``owners``' row fields, each owner pointed at its row (unlinkable ones stay plain)."""
    fields = _fields(ctype)
    values = {f.name: [f.raw(o) for o in owners] for f in fields}
    block = RowBlock()
    for f in fields:
        made = f.column(values[f.name])
        if made is None:  # a value the block cannot hold exactly: the batch stays plain objects
            for o in owners:
                if o.__dict__.get(_LINK) is not None:
                    _unlink(o)
            block.stale = block.failed = True
            return block
        block.arrays[f.name], present = made
        if present is not None:
            block.present[f.name] = present
    for row, o in enumerate(owners):
        d = o.__dict__
        for f in fields:
            d.pop(f.name, None)
        d[_LINK] = (block, row)
    return block


def row_store(world: World) -> RowStore:
    """The world's :class:`RowStore` resource (inserted on first use)."""
    found = world.try_resource(RowStore)
    if found is None:
        found = RowStore()
        world.insert_resource(found)
    return found
