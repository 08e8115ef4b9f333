"""The ragdoll bench runs to its end and says what a join costs (no timing asserted)."""

from __future__ import annotations

from puppetphone.bench.ragdoll import run


def test_the_ragdoll_bench_times_joins_that_take_pool_slots_without_compiling() -> None:
    figures = {f.name: f for f in run()}
    assert {"ragdoll_step_ms_1", "ragdoll_step_ms_10", "ragdoll_add_ms", "ragdoll_track_error_deg"} <= set(figures)
    assert figures["ragdoll_add_ms"].value > 0
    assert figures["ragdoll_add_rebuilds"].value == 0  # the first crowd's pool had room for the five joins
