"""The batch's process pool: its workers do not outlive a main process killed with ``kill -9``."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
import uuid
from pathlib import Path

import pytest

MAIN = textwrap.dedent("""
    import time
    from authoring.batch.runner import _pool
    from authoring.batch.worker import BatchOptions, TakeTask
    tasks = [TakeTask(f"/nonexistent/{i}.bvh", f"{i:064x}") for i in range(3)]
    outcomes = _pool(tasks, BatchOptions(), 2, None)
    next(outcomes)  # the pool is up, its workers wait for more
    print("ready", flush=True)
    time.sleep(600)
""")


def _marked(mark: str) -> set[int]:
    """Processes whose environment carries ``mark`` (the main process, the forkserver, the workers)."""
    found = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if mark.encode() in (entry / "environ").read_bytes():
                    found.add(int(entry.name))
            except OSError:
                continue
    return found


@pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs Linux /proc to find the workers")
def test_workers_end_soon_after_the_main_process_is_killed() -> None:
    mark = f"PP_BATCH_TEST={uuid.uuid4().hex}"
    env = {**os.environ, mark.split("=")[0]: mark.split("=")[1]}
    main = subprocess.Popen([sys.executable, "-c", MAIN], env=env, stdout=subprocess.PIPE, text=True)
    try:
        assert main.stdout is not None and main.stdout.readline().strip() == "ready"
        workers = _marked(mark) - {main.pid}
        assert len(workers) >= 2
        main.send_signal(signal.SIGKILL)
        main.wait(10)
        end = time.monotonic() + 15.0
        while _marked(mark) and time.monotonic() < end:
            time.sleep(0.1)
        assert not _marked(mark), "pool workers outlived the killed main process"
    finally:
        main.kill()
        main.wait(10)
        if main.stdout is not None:
            main.stdout.close()
        for pid in _marked(mark):
            os.kill(pid, signal.SIGKILL)
