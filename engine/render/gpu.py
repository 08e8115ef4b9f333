"""Small moderngl helpers shared by the render passes."""

from __future__ import annotations

from typing import Any, Protocol

import moderngl
import numpy as np
from numpy.typing import NDArray

__all__ = ["Instances", "LodBatches", "Releasable", "set_uniform", "mesh_buffers"]


class Releasable(Protocol):
    """A GPU object freed by ``release()`` (buffers, programs, textures, framebuffers, arrays share no base class)."""

    def release(self) -> None: ...


class Instances:
    """A dynamic instance buffer that grows by orphaning, so VAO bindings stay valid."""

    def __init__(self, ctx: moderngl.Context, stride_bytes: int) -> None:
        self.buf = ctx.buffer(reserve=max(stride_bytes * 64, 1024), dynamic=True)
        self.count = 0

    def upload(self, data: NDArray[np.float32]) -> int:
        """Write ``data`` rows (float32) and return how many instances that is."""
        raw = np.ascontiguousarray(data, dtype=np.float32).tobytes()
        if len(raw) > self.buf.size:
            self.buf.orphan(2 * len(raw))
        if raw:
            self.buf.write(raw)
        self.count = len(data)
        return self.count


def set_uniform(prog: moderngl.Program, name: str, value: Any) -> None:
    """Set a uniform if the compiler kept it (unused uniforms are optimised away).

    ``[4,4]`` numpy matrices (maths convention, column vectors) are uploaded transposed,
    since GL reads them column-major.
    """
    u = prog.get(name, None)  # not ``name in prog``: Program has no __contains__, that scans its members
    if not isinstance(u, moderngl.Uniform):  # optimised away, or an attribute or varying: nothing to set
        return
    if isinstance(value, np.ndarray) and value.shape == (4, 4):
        u.write(np.ascontiguousarray(value.T, dtype=np.float32).tobytes())
    else:
        u.value = value


def mesh_buffers(
    ctx: moderngl.Context, mesh: tuple[NDArray[Any], NDArray[Any]]
) -> tuple[moderngl.Buffer, moderngl.Buffer]:
    """Vertex and index buffers of a ``(vertices, triangles)`` mesh."""
    return ctx.buffer(np.ascontiguousarray(mesh[0]).tobytes()), ctx.buffer(np.ascontiguousarray(mesh[1]).tobytes())


class LodBatches:
    """Capsules (or spheres) drawn with one instanced call per level of detail.

    Args:
        ctx: the context.
        program: the program every level draws with (its vertex stage reads ``in_vert``
            and the capsule instance attributes ``fmt``).
        meshes: one ``(vertices, triangles)`` unit mesh per level, coarse to fine.
        fmt: the instance layout, e.g. ``("3f 3f 1f 3f 1f/i", "i_a", ...)``, of rows
            ``stride_bytes`` long.
    """

    def __init__(
        self,
        ctx: moderngl.Context,
        program: moderngl.Program,
        meshes: list[tuple[NDArray[Any], NDArray[Any]]],
        fmt: tuple[str, ...],
        stride_bytes: int,
    ) -> None:
        self._levels: list[tuple[moderngl.VertexArray, Instances]] = []
        self._buffers: list[moderngl.Buffer] = []
        for mesh in meshes:
            vbo, ibo = mesh_buffers(ctx, mesh)
            inst = Instances(ctx, stride_bytes)
            self._buffers += [vbo, ibo, inst.buf]
            self._levels.append(
                (ctx.vertex_array(program, [(vbo, "4f", "in_vert"), (inst.buf, *fmt)], ibo, 4, skip_errors=True), inst)
            )

    def upload(self, rows: NDArray[np.float32], level: NDArray[np.intp]) -> None:
        """Give each level the rows whose ``level`` index names it (order kept)."""
        for i, (_, inst) in enumerate(self._levels):
            inst.upload(rows[level == i])

    def render(self) -> None:
        """One instanced draw per level that has rows."""
        for vao, inst in self._levels:
            if inst.count:
                vao.render(moderngl.TRIANGLES, instances=inst.count)

    def release(self) -> None:
        """Free the vertex arrays and buffers."""
        for vao, _ in self._levels:
            vao.release()
        for buf in self._buffers:
            buf.release()
