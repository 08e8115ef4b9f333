"""The period search: the paper's minimal-T rule with tempo drift, misses and outliers."""

from __future__ import annotations

import numpy as np

from authoring.cycles.descriptor import Descriptor
from authoring.cycles.period import PeriodSearch, candidate_minima, match_chain, search_periods


def _sine_rows(period_samples: float, n: int, points: list[int]) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / 60.0
    phase = np.arange(n) / period_samples
    v = np.stack(
        [
            np.sin(2 * np.pi * phase + 0.3) + 0.2 * np.sin(6 * np.pi * phase + 2.0),
            0.4 * np.sin(4 * np.pi * phase + 1.0),
        ],
        axis=1,
    )
    return t, Descriptor(t, v).rows(points)


def test_minimal_period_is_the_true_one_not_a_multiple() -> None:
    t, rows = _sine_rows(50, 400, [63, 207])
    per = search_periods(t, rows, np.array([63, 207]), PeriodSearch())
    assert np.all(np.abs(per - 50) <= 50 / 8)


def test_chain_refines_to_the_true_period() -> None:
    t, rows = _sine_rows(47.3, 500, [100])
    per = search_periods(t, rows, np.array([100]), PeriodSearch())
    chain = match_chain(t, rows[0], 100, int(per[0]), PeriodSearch())
    assert abs(chain.period * 60 - 47.3) < 0.5
    assert np.all(np.diff(chain.repetition) >= 1)
    assert 100 in chain.matches


def test_tempo_drift_is_followed() -> None:
    # The performer slows down by 20 % over the take; the chain follows the last match.
    n = 600
    t = np.arange(n) / 60.0
    phase = np.cumsum(1.0 / np.linspace(45, 54, n))
    v = np.stack([np.sin(2 * np.pi * phase), np.cos(4 * np.pi * phase)], axis=1)
    rows = Descriptor(t, v).rows([300])
    per = search_periods(t, rows, np.array([300]), PeriodSearch())
    assert 40 <= per[0] <= 56
    chain = match_chain(t, rows[0], 300, int(per[0]), PeriodSearch())
    assert len(chain.matches) >= 10


def test_noise_dips_are_outliers() -> None:
    row = np.full(200, 10.0)
    row[[20, 70, 120, 170]] = 0.05  # true repetitions
    row[[45, 95, 145]] = 3.0  # shallow look-alikes under a median threshold
    row[30] = 9.9  # a noise wiggle
    j = candidate_minima(row, PeriodSearch(threshold_quantile=0.99))
    assert set(j.tolist()) == {20, 70, 120, 170}
