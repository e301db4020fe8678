"""Recipe: a design sweep on a real Dask cluster, started as separate processes on loopback.

It starts `dask scheduler` and two `dask worker` processes on 127.0.0.1 (as you would on a
cluster, one command per machine), runs a small version of `actuator-fmus sweep`
(bladder pre-strain x wall thickness -> net work per stroke of Table 2.1's muscle A at 690 kPa,
thick wall, eq. 2.19-2.20) through `--scheduler`, and stops the processes it started, also on
failure. The FMU travels to the workers as bytes, so they need no shared file system.
Run after `make fmus`: .venv/bin/python recipes/dask_sweep_real_scheduler.py
"""
import math
import socket
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DASK = str(Path(sys.executable).with_name("dask"))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_workers(address, n, timeout=120.0):
    from dask.distributed import Client

    with Client(address, timeout=timeout) as client:
        client.wait_for_workers(n, timeout=timeout)
        return len(client.scheduler_info()["workers"])


def main():
    from actuator_fmus import sweep as sweep_dask

    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    procs = [subprocess.Popen([DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], **quiet)]
    try:
        time.sleep(1.0)
        procs.append(subprocess.Popen([DASK, "worker", address, "--host", "127.0.0.1", "--nworkers", "2",
                                       "--nthreads", "1", "--no-dashboard", "--memory-limit", "1GiB"],
                                      **quiet))
        workers = wait_for_workers(address, 2)
        print(f"scheduler {address} (pid {procs[0].pid}), {workers} workers (pid {procs[1].pid})")
        prestrains = sweep_dask.linspace(0.0, 0.9, 4)
        thicknesses = sweep_dask.linspace(0.4e-3, 2.4e-3, 3)
        rows, seconds = sweep_dask.sweep(prestrains, thicknesses, scheduler=address, batch=3, layers=8,
                                         n_lengths=100, progress=False)
        print(f"{len(rows)} runs in {seconds:.2f} s on the cluster")
        print("pre-strain  wall [mm]  net work per stroke at 690 kPa [J]")
        for prestrain, thickness, work in rows:
            text = "does not fit the sleeve" if math.isnan(work) else f"{work:.4f}"
            print(f"{100 * prestrain:9.0f}%  {1e3 * thickness:9.2f}  {text}")
        assert len(rows) == len(prestrains) * len(thicknesses)
        works = [w for _, _, w in rows if not math.isnan(w)]
        assert len(works) >= len(rows) - 3 and all(0.0 < w < 10.0 for w in works), rows
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
    assert all(p.poll() is not None for p in procs)
    print("scheduler and workers stopped")


if __name__ == "__main__":
    main()
