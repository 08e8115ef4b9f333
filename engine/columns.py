"""Columns: one array field of many components kept as the rows of one array the components view.

A crowd's hot per-puppet arrays (local poses, world poses, foot locks) are written by one
system and read by the next every step. Gathering them from a hundred component objects
(``np.array([c.rotations for c in comps])``) and scattering the results back
(``for k, c in enumerate(comps): c.rotations = out[k]``) is Python work per puppet that
costs more than the compiled kernels in between. A :class:`Column` keeps the field of a
fixed list of components (a batch, in a fixed row order) as one ``[N, ...]`` array and
sets each component's field to a *view* of its row, once. From then on:

- :meth:`Column.write` copies a batch's new values into the array in place: every
  component sees its row, and no component is touched.
- :meth:`Column.read` hands out the array itself: no gather.

The components stay plain objects that any code may read and assign as before. A
component whose field was replaced by other code (``pose.rotations = other``, a state's
override) no longer views its row; both methods notice it and take the new value in
(``read``) or re-link the row (``write``), so a puppet in an unusual state costs a little
Python and the crowd none. To notice it without comparing every row on every call, the
field of a dataclass gets an *assignment log* the first time a column holds it: a
descriptor with only ``__set__`` (reads stay plain ``__dict__`` reads, in C) that
notes each component assigned. A column looks only at the components assigned since it
last looked, so it is validated when a field changes, not on every access; a field the
log cannot be put on (a slot, a property, owners of several classes) is compared row by
row in one pass in C, as before. The same logs let a system keep values it set on many
components while nobody assigned them (:func:`assignment_mark`, :func:`unassigned_since`). What changes for other code: a field that views a
column is overwritten in place by the next write, so a reference kept across steps must be
a copy (``np.array(c.rotations)``), as with any array that a system updates in place.

A column of a batch whose members change (a puppet spawned or removed, a group that
splits) is rebuilt from the components' current values: correct whatever happened, and
only as costly as the gather it replaces.
"""

from __future__ import annotations

from collections.abc import Sequence
from operator import attrgetter, is_
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine.ecs import World

__all__ = ["Column", "Columns", "Mark", "Stacked", "assignment_mark", "columns", "unassigned_since"]


class Column:
    """Field ``attr`` of a batch of components, as rows of one array they view.

    Args:
        attr: the field's name on each component.
        dtype: the array's type (a field of another type is converted when taken in).
    """

    __slots__ = (
        "attr",
        "dtype",
        "_get",
        "_ids",
        "_owners",
        "_parts",
        "_row",
        "base",
        "_views",
        "_wholes",
        "_watch",
        "_epoch",
        "_seen",
        "_suspect",
    )

    def __init__(self, attr: str, dtype: type = np.float64) -> None:
        self.attr = attr
        self.dtype = dtype
        self._get = attrgetter(attr)
        self._ids: list[int] = []
        self._owners: list[Any] = []
        self._row: dict[int, int] = {}
        self.base: NDArray[Any] | None = None
        self._views: list[NDArray[Any]] = []
        self._wholes: dict[int, tuple[Any, ...]] = {}  # tuples of owners found to be the whole column, by id
        # Tuples of owners found in the column (by id, kept so no id is reused): their rows, as an array and a set.
        self._parts: dict[int, tuple[tuple[Any, ...], NDArray[np.int64], frozenset[int]]] = {}
        self._watch: _Watched | None = None  # the owners' field's assignment log, when their class has one
        self._epoch = -1  # the log's epoch and length when it was last read
        self._seen = 0
        self._suspect: set[int] = set()  # rows that may have been assigned since: every other row views its row

    def _rows(self, owners: Sequence[Any]) -> slice | list[int] | None:
        """Where ``owners`` are in the column: all of it in order (``slice(None)``), some of its rows,
        or ``None`` when one is not in it (or the rows are no views of the array: a copied world)."""
        if self.base is None or (self._views and self._views[0].base is not self.base):
            return None
        if self._wholes.get(id(owners)) is owners:  # a tuple cannot have changed: no id to compare
            return _ALL
        ids = list(map(id, owners))
        if ids == self._ids:
            if isinstance(owners, tuple):
                if len(self._wholes) >= _PARTS:
                    self._wholes.clear()
                self._wholes[id(owners)] = owners
            return _ALL
        row = self._row
        try:
            return list(map(row.__getitem__, ids))
        except KeyError:
            return None

    def _replaced(self) -> set[int]:
        """The rows whose field no longer is the view of its row (other code assigned it).

        With the owners' assignment log (:func:`_watched`) only the owners assigned since the last
        call are looked at: a crowd nobody touched costs no Python per row. Without one (a class
        the log cannot be put on) every row is compared, in one pass in C."""
        owners, views, get = self._owners, self._views, self._get
        watch = self._watch
        if watch is None or watch.epoch != self._epoch:
            if watch is not None:
                self._epoch, self._seen = watch.epoch, len(watch.log)
            if all(map(is_, map(get, owners), views)):
                self._suspect = set()
            else:
                self._suspect = {i for i, (o, v) in enumerate(zip(owners, views, strict=True)) if get(o) is not v}
            return self._suspect
        log = watch.log
        suspect = self._suspect
        if len(log) != self._seen:
            row = self._row
            for o in log[self._seen :]:
                i = row.get(id(o))
                if i is not None and owners[i] is o:
                    suspect.add(i)
            self._seen = len(log)
        if suspect:
            for i in [i for i in suspect if get(owners[i]) is views[i]]:
                suspect.discard(i)
        return suspect

    def _sync(self, rows: slice | list[int], take_in: bool) -> bool:
        """Point the fields replaced by other code at their rows again, first copying their values in
        if ``take_in``; ``False`` (and nothing re-linked after it) if such a value has another shape."""
        replaced = self._replaced()
        if not replaced:
            return True
        owners, views = self._owners, self._views
        todo = sorted(replaced) if isinstance(rows, slice) else sorted(replaced.intersection(rows))
        for i in todo:
            now = self._get(owners[i])
            if take_in:
                value: NDArray[Any] = np.asarray(now, dtype=self.dtype)
                if value.shape != views[i].shape:
                    return False
                views[i][...] = value
            setattr(owners[i], self.attr, views[i])
            replaced.discard(i)
        return True

    def _intact(self) -> bool:
        """Whether every owner's field is still the view of its row."""
        return not self._replaced()

    def _link(self, owners: Sequence[Any], base: NDArray[Any]) -> NDArray[Any]:
        """Make ``base`` the column of ``owners`` and point every component's field at its row."""
        if base.ndim < 2:
            raise ValueError(f"a column holds array fields, one row each: {self.attr} has shape {base.shape[1:]}")
        self.base, self._owners, self._ids = base, list(owners), list(map(id, owners))
        self._wholes = {}
        self._parts = {}
        self._row = {k: i for i, k in enumerate(self._ids)}
        self._views = list(base)
        for owner, view in zip(owners, self._views, strict=True):
            setattr(owner, self.attr, view)
        self._watch = _watched(self._owners, self.attr)
        self._suspect = set()
        if self._watch is not None:
            self._epoch, self._seen = self._watch.epoch, len(self._watch.log)
        return base

    def read(self, owners: Sequence[Any]) -> NDArray[Any]:
        """The field of every component of ``owners`` as one array ``[N, ...]``.

        For the column's whole batch it is the column itself (no copy): changing it in place
        changes the components' fields. For part of the batch it is a copy of their rows.
        A field replaced since the last call is taken in first; components not in the
        column (or a replaced field of another shape) build it anew from their fields.
        """
        rows = self._rows(owners)
        if rows is None or not self._sync(rows, take_in=True):
            return self._link(owners, np.array([self._get(o) for o in owners], dtype=self.dtype))
        assert self.base is not None
        return self.base if rows is _ALL else self.base[rows]

    def linked(self, owners: Sequence[Any]) -> NDArray[Any] | None:
        """The column itself when it is the field of exactly ``owners``, in order, and no field was
        replaced since; ``None`` otherwise (then :meth:`read` takes the fields in). A crowd in its usual
        state is checked without Python per row, and a kernel may then update it in place."""
        if self._rows(owners) is not _ALL or not self._intact():
            return None
        return self.base

    def rows(self, owners: tuple[Any, ...]) -> tuple[NDArray[Any], NDArray[np.int64]] | None:
        """The column and the rows ``[N]`` of ``owners`` in it, any field replaced since taken in first
        (as :meth:`read` does), for a kernel that reads or updates those rows in place; ``None`` when
        one of ``owners`` is not in the column or a replaced field has another shape.

        ``owners`` may be part of the column's batch (a crowd with one puppet in the air, ten fallen):
        their rows are looked up once per tuple, so only a puppet whose field was replaced costs Python."""
        if self.base is None or (self._views and self._views[0].base is not self.base):
            return None
        part = self._parts.get(id(owners))
        if part is None or part[0] is not owners:
            found = self._rows(owners)
            if found is None:
                return None
            index = list(range(len(self._owners))) if isinstance(found, slice) else found
            part = (owners, np.array(index, dtype=np.int64), frozenset(index))
            if len(self._parts) >= _PARTS:
                self._parts.clear()
            self._parts[id(owners)] = part
        replaced = self._replaced()
        if replaced and not replaced.isdisjoint(part[2]) and not self._sync(part[1].tolist(), take_in=True):
            return None
        return self.base, part[1]

    def write(self, owners: Sequence[Any], values: ArrayLike) -> None:
        """Set the field of every component of ``owners`` to its row of ``values`` ``[N, ...]`` (copied)."""
        values = np.asarray(values, dtype=self.dtype)
        rows = self._rows(owners)
        if rows is _ALL and values is self.base:  # changed in place: what read handed out
            return
        if rows is None or self.base is None or self.base.shape[1:] != values.shape[1:] or len(values) != len(owners):
            self._link(owners, values.copy())
            return
        self._sync(rows, take_in=False)
        self.base[rows] = values


class _Watched:
    """The assignment log of one field of a component class: a data descriptor with only ``__set__``.

    Reading the field is untouched (a descriptor without ``__get__`` leaves reads to the
    instance's ``__dict__``, in C); assigning it stores the value there, as a plain field
    does, and appends the component to :attr:`log`. A column of that field then finds the
    components some code replaced the field of among the few assigned since it last looked,
    instead of comparing every row each call. The log is cleared when it grows past
    :data:`_LOG_CAP` (a new :attr:`epoch`: a column that missed entries compares every row once);
    it holds the components, so an id in it is never reused while it is there. :attr:`count` counts every assignment
    ever (it never goes back, unlike the log's length): what a :class:`Mark` compares."""

    __slots__ = ("name", "log", "epoch", "count")

    def __init__(self, name: str) -> None:
        self.name = name
        self.log: list[Any] = []
        self.epoch = 0
        self.count = 0

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self.name] = value
        log = self.log
        if len(log) >= _LOG_CAP:
            log.clear()
            self.epoch += 1
        log.append(obj)
        self.count += 1

    def __delete__(self, obj: Any) -> None:
        del obj.__dict__[self.name]
        self.log.append(obj)
        self.count += 1


_LOG_CAP = 8192


def _watched(owners: Sequence[Any], attr: str) -> _Watched | None:
    """The assignment log of ``attr`` of the owners' class (see :func:`_field_log`); ``None`` when the owners are of
    several classes or the field cannot have one: then a column compares every row."""
    if not owners:
        return None
    cls = type(owners[0])
    if any(type(o) is not cls for o in owners):
        return None
    return _field_log(cls, attr)


class Mark:
    """Where the assignment logs of some fields stood (:func:`assignment_mark`): each log's :attr:`_Watched.count`,
    kept as a tuple so that :func:`unassigned_since` compares them in C, without a Python step per field."""

    __slots__ = ("_logs", "_at")

    def __init__(self, logs: tuple[_Watched, ...]) -> None:
        self._logs = logs
        self._at = tuple(map(_COUNT, logs))

    def unchanged(self) -> bool:
        """Whether no log took an assignment since the mark was taken."""
        return tuple(map(_COUNT, self._logs)) == self._at


_COUNT = attrgetter("count")


def assignment_mark(cls: type, attrs: Sequence[str]) -> Mark | None:
    """Where the assignment logs of the fields ``attrs`` of ``cls`` stand now (the logs put on the class on first use);
    ``None`` if one of them cannot have a log. A system that set those fields of many components to values that
    hold until someone assigns them keeps the mark, and skips setting them again while :func:`unassigned_since`."""
    logs = [_field_log(cls, attr) for attr in attrs]
    if any(log is None for log in logs):
        return None
    return Mark(tuple(log for log in logs if log is not None))


def unassigned_since(mark: Mark | None) -> bool:
    """Whether no component of the marked class had one of the marked fields assigned since the mark was taken."""
    return mark is not None and mark.unchanged()


def _field_log(cls: type, attr: str) -> _Watched | None:
    """The assignment log of field ``attr`` of the class ``cls``, put on the class on first use; ``None`` when the
    field is not a plain instance field (a slot, a property, a row field of :mod:`engine.rows`, a class attribute
    other than the dataclass default)."""
    key = (cls, attr)
    if key not in _LOGS:
        _LOGS[key] = _new_field_log(cls, attr)
    return _LOGS[key]


_LOGS: dict[tuple[type, str], _Watched | None] = {}


def _new_field_log(cls: type, attr: str) -> _Watched | None:
    if "__dict__" not in dir(cls):
        return None
    for klass in cls.__mro__:
        if attr in klass.__dict__:
            found = klass.__dict__[attr]
            if isinstance(found, _Watched):
                return found
            spec = getattr(klass, "__dataclass_fields__", {}).get(attr)
            if klass is not cls or spec is None or found is not spec.default or hasattr(type(found), "__get__"):
                return None
            break
    else:
        spec = getattr(cls, "__dataclass_fields__", {}).get(attr)
        if spec is None:
            return None
    made = _Watched(attr)
    setattr(cls, attr, made)
    return made


_ALL = slice(None)
_PARTS = 8  # owner tuples whose rows a column remembers (a few stages ask about a few crowds)


class Columns:
    """Resource: the columns of a world, by (component type, field, batch key). Not simulation state:
    the values live in the components (the columns are how they are stored), so it is never hashed."""

    SIM_STATE = False

    def __init__(self) -> None:
        self._columns: dict[tuple[type, str, object], Column] = {}
        self._stacks: dict[object, Stacked] = {}

    def get(self, ctype: type, attr: str, key: object = None, dtype: type = np.float64) -> Column:
        """The column of field ``attr`` of ``ctype`` for the batch named ``key`` (made on first use)."""
        column = self._columns.get((ctype, attr, key))
        if column is None:
            column = self._columns[(ctype, attr, key)] = Column(attr, dtype)
        return column

    def stacked(self, key: object) -> Stacked:
        """The :class:`Stacked` cache named ``key`` (made on first use)."""
        stack = self._stacks.get(key)
        if stack is None:
            stack = self._stacks[key] = Stacked()
        return stack


def columns(world: World) -> Columns:
    """The world's :class:`Columns` resource (inserted on first use)."""
    found = world.try_resource(Columns)
    if found is None:
        found = Columns()
        world.insert_resource(found)
    return found


class Stacked:
    """The stack ``[N, ...]`` of a batch's arrays that do not change in place (a skeleton's offsets).

    Rebuilt only when one of the arrays is another object than last time (it keeps them, so
    an id is never reused while cached). The result is shared: read it, never change it.
    """

    __slots__ = ("_arrays", "_ids", "_stack")

    def __init__(self) -> None:
        self._arrays: list[Any] = []
        self._ids: list[int] = []
        self._stack: NDArray[np.float64] | None = None

    def __call__(self, arrays: Sequence[Any]) -> NDArray[np.float64]:
        """The stack of ``arrays`` (float64)."""
        ids = list(map(id, arrays))
        if self._stack is None or ids != self._ids:
            self._arrays, self._ids = list(arrays), ids
            self._stack = np.array(arrays, dtype=np.float64)
        return self._stack
