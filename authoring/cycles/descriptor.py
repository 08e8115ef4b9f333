"""The curve descriptor of paper §4: which points of a performance look alike.

For each sample ``i`` the descriptor stacks, for ``k = 0..K`` (K = 5 in the paper),

    ĥ_i^k = Σ_{|i-j|≤k} θ'_j        ĝ_i^k = Σ_{|i-j|≤k} θ''_j

with ``θ'`` and ``θ''`` central differences over the (possibly uneven) times, and the
dissimilarity of two points is ``d_D(i,j) = ‖h_i − h_j‖ · ‖g_i − g_j‖``. Being built
from derivatives it ignores slow offsets (drift) and compares *shape and speed*,
which is what makes matching points across imprecise repetitions possible.

Why it is computed the way it is: the full descriptor is ``T × 6N`` per kind, which
for the paper's 7,804-dimension cloth and a few hundred frames is hundreds of
megabytes, and the algorithm only asks for *rows* ``d_D(i, ·)`` of a few chosen points,
with ``‖a − b‖² = ‖a‖² + ‖b‖² − 2a·b``. Three exact strategies, picked by size:

* **stacked** (small ``T·N``): keep ``h`` and ``g`` whole; a row is one matrix product.
* **Gram** (more dimensions than samples, the cloth): every needed inner product is a
  box sum of the ``T × T`` Gram matrix ``G = θ' θ'ᵀ`` (``ĥ^k_i · ĥ^k_j`` sums ``G`` over a
  ``(2k+1)²`` box), read from its summed-area table; ``g``'s Gram is ``D G Dᵀ`` with ``D``
  the difference operator. One BLAS product of the data, then only ``T × T`` work.
* **streaming** (long and wide): accumulate window size by window size, each window
  sum one in-place add of two shifted copies of the derivative array, each cross term
  one product against the query rows; memory stays at a few ``T × N`` arrays.
"""

from __future__ import annotations

from collections.abc import Iterator
from functools import reduce

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["K_DEFAULT", "STRATEGIES", "Descriptor", "central_difference"]

K_DEFAULT = 5
CACHE_LIMIT = 4_000_000  # numbers, i.e. 32 MB of float64
GRAM_MAX_SAMPLES = 3000  # a T × T table beyond this costs more than it saves
STRATEGIES = ("auto", "stacked", "gram", "stream")


def central_difference(times: NDArray[np.float64], values: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(θ_{j+1} − θ_{j−1}) / (t_{j+1} − t_{j−1})`` inside, one-sided differences at the two ends."""
    n = len(times)
    out = np.empty_like(values)
    if n < 2:
        out[:] = 0.0
        return out
    if n > 2:
        out[1:-1] = (values[2:] - values[:-2]) / (times[2:] - times[:-2])[:, None]
    out[0] = (values[1] - values[0]) / (times[1] - times[0])
    out[-1] = (values[-1] - values[-2]) / (times[-1] - times[-2])
    return out


def _window_sums(x: NDArray[np.float64], k_max: int) -> Iterator[NDArray[np.float64]]:
    """Yield ``Σ_{|i−j|≤k} x_j`` for k = 0..k_max, reusing one buffer (ends repeat the edge sample)."""
    n = len(x)
    pad = np.concatenate([np.repeat(x[:1], k_max, axis=0), x, np.repeat(x[-1:], k_max, axis=0)])
    acc = x.copy()
    yield acc
    for k in range(1, k_max + 1):
        acc += pad[k_max - k : k_max - k + n]
        acc += pad[k_max + k : k_max + k + n]
        yield acc


class _GramRows:
    """Inner products of window sums read from a summed-area table of a Gram matrix."""

    def __init__(self, gram: NDArray[np.float64], k_max: int) -> None:
        n = len(gram)
        idx = np.clip(np.arange(-k_max, n + k_max), 0, n - 1)  # edge samples repeat, as in streaming
        padded = gram[np.ix_(idx, idx)]
        self.table = np.zeros((n + 2 * k_max + 1, n + 2 * k_max + 1))
        self.table[1:, 1:] = padded.cumsum(axis=0).cumsum(axis=1)
        i = np.arange(n)
        self.bounds = [(i + k_max - k, i + k_max + k + 1) for k in range(k_max + 1)]
        self.own = reduce(np.add, (self._box(a, b, a, b, diagonal=True) for a, b in self.bounds))

    def _box(
        self,
        a: NDArray[np.int64],
        b: NDArray[np.int64],
        c: NDArray[np.int64],
        d: NDArray[np.int64],
        diagonal: bool = False,
    ) -> NDArray[np.float64]:
        s = self.table
        if diagonal:
            return s[b, d] - s[a, d] - s[b, c] + s[a, c]
        return s[np.ix_(b, d)] - s[np.ix_(a, d)] - s[np.ix_(b, c)] + s[np.ix_(a, c)]

    def sq_distances(self, q: NDArray[np.int64]) -> NDArray[np.float64]:
        cross = reduce(np.add, (self._box(a[q], b[q], a, b) for a, b in self.bounds))
        return np.maximum(self.own[q][:, None] + self.own[None, :] - 2.0 * cross, 0.0)


class Descriptor:
    """Rows of ``d_D`` for chosen points of one performance.

    Args:
        times: ``[T]`` increasing seconds.
        values: ``[T, N]`` values (already weighted by the caller).
        k: largest window half-width (the paper uses 5).
        strategy: one of :data:`STRATEGIES`; ``auto`` picks by size (all give the same rows).
        cache_limit: ``auto`` keeps the whole stacked descriptor when it has at most this many numbers.
    """

    def __init__(
        self,
        times: ArrayLike,
        values: ArrayLike,
        k: int = K_DEFAULT,
        strategy: str = "auto",
        cache_limit: int = CACHE_LIMIT,
    ) -> None:
        t = np.asarray(times, dtype=np.float64)
        v = np.asarray(values, dtype=np.float64)
        if v.ndim != 2 or len(v) != len(t):
            raise ValueError(f"values must be [T,N] matching {len(t)} times, got {v.shape}")
        if k < 0:
            raise ValueError(f"window half-width must be ≥ 0, got {k}")
        if strategy not in STRATEGIES:
            raise ValueError(f"strategy must be one of {STRATEGIES}, got {strategy!r}")
        n, dims = v.shape
        if strategy == "auto":
            if 2 * (k + 1) * v.size <= cache_limit:
                strategy = "stacked"
            elif n <= dims and n <= GRAM_MAX_SAMPLES:
                strategy = "gram"
            else:
                strategy = "stream"
        self.k = int(k)
        self.times = t
        self.strategy = strategy
        self._d1 = central_difference(t, v)
        self._d2: NDArray[np.float64] | None = None
        self._norms: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self._stacked: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self._gram: tuple[_GramRows, _GramRows] | None = None
        if strategy == "gram":
            g1 = self._d1 @ self._d1.T
            g2 = central_difference(t, central_difference(t, g1).T)  # D G Dᵀ (G symmetric)
            self._gram = (_GramRows(g1, self.k), _GramRows(g2, self.k))
            return
        self._d2 = central_difference(t, self._d1)
        if strategy == "stacked":
            self._stacked = (self._stack(self._d1), self._stack(self._d2))
            self._norms = (
                np.einsum("ij,ij->i", self._stacked[0], self._stacked[0]),
                np.einsum("ij,ij->i", self._stacked[1], self._stacked[1]),
            )

    def _stack(self, deriv: NDArray[np.float64]) -> NDArray[np.float64]:
        """``[T, (K+1)·N]``: the window sums side by side (the paper's stacked descriptor)."""
        n, dims = deriv.shape
        out = np.empty((n, (self.k + 1) * dims))
        for k, h in enumerate(_window_sums(deriv, self.k)):
            out[:, k * dims : (k + 1) * dims] = h
        return out

    @property
    def num_samples(self) -> int:
        """Number of samples ``T``."""
        return len(self.times)

    def _sq_distances(
        self, deriv: NDArray[np.float64], queries: NDArray[np.int64], norms: NDArray[np.float64] | None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``Σ_k ‖H^k_q − H^k_j‖²`` as ``[Q, T]``, plus the per-sample ``Σ_k ‖H^k_j‖²`` (computed if not given)."""
        n = len(deriv)
        cross = np.zeros((len(queries), n))
        own = np.zeros(n) if norms is None else norms
        for h in _window_sums(deriv, self.k):
            hq = h[queries]
            cross += hq @ h.T
            if norms is None:
                own += np.einsum("ij,ij->i", h, h)
        sq = own[queries][:, None] + own[None, :] - 2.0 * cross
        np.maximum(sq, 0.0, out=sq)
        return sq, own

    def rows(self, queries: ArrayLike) -> NDArray[np.float64]:
        """``d_D(q, j)`` for every query index ``q`` and every sample ``j``: ``[Q, T]``."""
        q = np.atleast_1d(np.asarray(queries, dtype=np.int64))
        if q.size and (q.min() < 0 or q.max() >= self.num_samples):
            raise IndexError(f"query indices must lie in [0, {self.num_samples})")
        if self._gram is not None:
            return np.sqrt(self._gram[0].sq_distances(q) * self._gram[1].sq_distances(q))
        if self._stacked is not None and self._norms is not None:
            out = np.ones((len(q), self.num_samples))
            for full, own in zip(self._stacked, self._norms, strict=True):
                sq = own[q][:, None] + own[None, :] - 2.0 * (full[q] @ full.T)
                out *= np.maximum(sq, 0.0)
            return np.sqrt(out)
        assert self._d2 is not None
        nh, ng = self._norms if self._norms is not None else (None, None)
        sh, nh = self._sq_distances(self._d1, q, nh)
        sg, ng = self._sq_distances(self._d2, q, ng)
        self._norms = (nh, ng)
        return np.sqrt(sh * sg)
