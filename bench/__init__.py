"""Benchmarks: each module ``bench/<name>.py`` has ``run() -> list[Figure]``.

``puppetphone bench NAME…`` runs them; every figure carries its baseline from the
same run, because these machines are shared and noisy and only ratios compare.
"""

from bench.figures import Figure, median_time

__all__ = ["Figure", "median_time", "BENCHES"]

# bench name on the command line -> module
BENCHES: dict[str, str] = {
    "fk": "bench.fk",
    "blend": "bench.blend",
    "ragdoll": "bench.ragdoll",
    "ik": "bench.ik",
    "cycles": "bench.cycles",
    "cycles-batch": "bench.cycles_batch",
    "mocurves": "bench.mocurves",
    "input-latency": "bench.input_latency",
    "phone-view": "bench.phone_view",
    "snowman": "bench.snowman",
    "render": "bench.render",
    "state-hash": "bench.state_hash",
    "crowd": "bench.crowd",
    "crowd-scale": "bench.crowd_scale",
    "startup": "bench.startup",
    "peers": "bench.peers",
    "clips": "bench.clips",
    "flow": "bench.flow",
    "qp": "bench.qp",
    "curves": "bench.curves",
    "motion": "bench.motion",
}
