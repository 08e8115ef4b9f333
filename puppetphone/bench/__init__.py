"""Benchmarks: each module ``bench/<name>.py`` has ``run() -> list[Figure]``.

``puppetphone bench NAME…`` runs them; every figure carries its baseline from the
same run, because these machines are shared and noisy and only ratios compare.
"""

from puppetphone.bench.figures import Figure, median_time

__all__ = ["Figure", "median_time", "BENCHES"]

# bench name on the command line -> module
BENCHES: dict[str, str] = {
    "fk": "puppetphone.bench.fk",
    "blend": "puppetphone.bench.blend",
    "ragdoll": "puppetphone.bench.ragdoll",
    "ik": "puppetphone.bench.ik",
    "cycles": "puppetphone.bench.cycles",
    "cycles-batch": "puppetphone.bench.cycles_batch",
    "mocurves": "puppetphone.bench.mocurves",
    "input-latency": "puppetphone.bench.input_latency",
    "phone-view": "puppetphone.bench.phone_view",
    "snowman": "puppetphone.bench.snowman",
    "render": "puppetphone.bench.render",
    "state-hash": "puppetphone.bench.state_hash",
    "crowd": "puppetphone.bench.crowd",
    "crowd-scale": "puppetphone.bench.crowd_scale",
    "startup": "puppetphone.bench.startup",
    "peers": "puppetphone.bench.peers",
    "clips": "puppetphone.bench.clips",
    "flow": "puppetphone.bench.flow",
    "qp": "puppetphone.bench.qp",
    "curves": "puppetphone.bench.curves",
    "motion": "puppetphone.bench.motion",
}
