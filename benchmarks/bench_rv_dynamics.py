"""RV reducer dynamics (issue 6, paper 004): compiled integrator vs solve_ivp, and error batches.

1. One output revolution at 1500 rpm input (4.84 s simulated + 0.1 s settling) of the paper's
   prototype with the Table 3 errors: compiled RK4 kernel (goal ≤ 1 s on one core) against
   ``scipy.integrate.solve_ivp`` (RK45) on the plain-Python right-hand side, in the same run
   (goal ≥ 200×), both DTEs printed. The plain baseline needs minutes for the full span, so by
   default it runs ``--baseline-span`` seconds and its time is scaled to the full span (its step
   is bound by stability, so its cost is linear in the span); ``--full-baseline`` runs it all.
2. Right-hand side alone (goal ≤ 2 µs per evaluation), timed in a compiled loop.
3. Compile (or cache-load) time of the kernels, reported separately.
4. Batch: ``--samples`` (64) random error realisations on 2 threads vs one after another;
   aggregate simulated seconds per wall second (goal ≥ 50); and a batch of 2 at the default chunk
   size on 1 and 2 workers (issue 12 goal: ≥ 1.6× on 2 workers), ``--repeats`` (15) alternating
   pairs, each after waiting for idle cores (``--quiet-wait``, 20 s at most in all), the median
   of the paired ratios (the verdict) and the best of each side printed, beside the bare
   compiled kernel on the same two runs in two plain threads (the machine's ceiling), the
   kernel's CPU per run on 1 and 2 workers, and the CPU the machine's other processes used
   meanwhile.
5. Strong baselines (issue 12), same run, CPU seconds: a hand-written numba RK4 loop on the same
   compiled right-hand side and step, reducing the DTE to its extremes (gearte's RK4 goal: within
   1.5× of it), and ``solve_ivp`` (RK45 and DOP853, rtol 1e-6) on the compiled right-hand side
   (on ``--baseline-span`` s, scaled).

6. Memory (issue 12): the ``dte`` analysis of ``li2023_rv_errors`` (run through the study, at
   ``--record-dt``) over 1 and over 20 output revolutions, each in a fresh process; peak resident
   memory from ``resource.getrusage(RUSAGE_SELF / RUSAGE_CHILDREN).ru_maxrss`` (goal: 20
   revolutions within 1.2× of 1). ``--report`` also builds and writes the report.

Run: ``PYTHONPATH=src python benchmarks/bench_rv_dynamics.py [--full-baseline]
[--only speed,batch,memory]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time

import numpy as np
from numba import njit

from gearte.models.rv_dynamics import RHS_WORK_SIZE, rv_dte, rv_rhs
from gearte.runners.rv_dynamics_sim import default_step, dte_batch, ode_system
from gearte.solvers.ode import integrate, kernels
from gearte.studies._rv_dynamics import batch_tolerances
from gearte.studies.rv_reducer import load_dynamic_model
from gearte.units import ARCSEC_PER_RAD


@njit(cache=True, nogil=True)
def _rhs_loop(n, y, args, out, work):
    acc = 0.0
    for k in range(n):
        y[0] = 1e-9 * k
        rv_rhs(1e-6 * k, y, args, out, work)  # a new time every call: no memo hits
        acc += out[-1]
    return acc


@njit(nogil=True)
def _rk4_hand(y0, t0, dt, n_steps, settle_steps, args, work_size):
    """The plainest RK4 a numba user writes on gearte's compiled rhs: fixed step, DTE extremes
    after settling; returns (max - min) of the DTE [rad]."""
    n = y0.size
    work = np.full(work_size, np.nan)
    y = y0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    tmp = np.empty(n)
    lo, hi = np.inf, -np.inf
    for s in range(n_steps):
        t = t0 + s * dt
        rv_rhs(t, y, args, k1, work)
        for i in range(n):
            tmp[i] = y[i] + 0.5 * dt * k1[i]
        rv_rhs(t + 0.5 * dt, tmp, args, k2, work)
        for i in range(n):
            tmp[i] = y[i] + 0.5 * dt * k2[i]
        rv_rhs(t + 0.5 * dt, tmp, args, k3, work)
        for i in range(n):
            tmp[i] = y[i] + dt * k3[i]
        rv_rhs(t0 + (s + 1) * dt, tmp, args, k4, work)
        for i in range(n):
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        if s + 1 >= settle_steps:
            o = rv_dte(t0 + (s + 1) * dt, y, args)
            lo = min(lo, o)
            hi = max(hi, o)
    return hi - lo


def _memory_child(revs: float, record_dt: float, report: bool) -> None:
    """One ``dte`` analysis over ``revs`` output revolutions; prints the peak memory [MiB]."""
    import tempfile
    import tomllib

    import gearte
    from gearte.cases import case_path
    from gearte.studies import RunOptions

    data = tomllib.loads(case_path("li2023_rv_errors").read_text())
    rpm = data["operation"]["input_speed_rpm"]
    model, _ = load_dynamic_model("li2023_rv_errors")
    f_out = model.params.frequencies()["output rotation"]
    assert abs(f_out - rpm / 60 / model.params.ratio) < 1e-9
    data["analyses"] = {
        "dte": {"duration_s": revs / f_out, "settle_s": 0.1, "record_dt_s": record_dt}
    }
    c0 = time.process_time()
    result = gearte.run_case(gearte.load_case(data), RunOptions(progress=False, workers=1))
    v = result["dte"].values
    if report:
        with tempfile.TemporaryDirectory() as tmp:
            gearte.write_outputs(result, tmp)
    cpu = time.process_time() - c0
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(
        f"MEMORY {revs:g} {own:.1f} {kids:.1f} {cpu:.2f} {v['dte_peak_to_peak [arcsec]']:.6f} "
        f"{v['spectrum_window [s]']:.4f} {v['dominant_dte_frequency [Hz]']:.4f}"
    )


def memory(record_dt: float, report: bool) -> None:
    """Peak memory of the dte analysis at 1 and 20 output revolutions, fresh process each."""
    rows = {}
    for revs in (1, 20):
        cmd = [sys.executable, __file__, "--memory-child", str(revs), "--record-dt", str(record_dt)]
        if report:
            cmd.append("--report")
        out = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy())
        line = [x for x in out.stdout.splitlines() if x.startswith("MEMORY")]
        if out.returncode or not line:
            print(out.stdout, out.stderr)
            raise SystemExit(f"memory child for {revs} revolutions failed")
        _, _, own, kids, cpu, p2p, window, dom = line[0].split()
        rows[revs] = (float(own), float(kids))
        print(
            f"dte analysis, {revs:2d} output revolution(s) at record_dt {record_dt:g} s: peak RSS "
            f"{float(own):7.1f} MiB (children {float(kids):6.1f} MiB), {float(cpu):6.2f} s CPU; "
            f"DTE p2p {float(p2p):.4f}″, spectrum window {float(window):.3f} s, dominant "
            f"{float(dom):.3f} Hz"
        )
    ratio = rows[20][0] / rows[1][0]
    verdict = "met" if ratio <= 1.2 else "NOT met"
    kids = f"; children (report renderers) {rows[20][1] / rows[1][1]:.2f}×" if rows[1][1] else ""
    print(f"goal peak memory 20 rev / 1 rev ≤ 1.2×: measured {ratio:.2f}× — {verdict}{kids}")


def _busy_s() -> float | None:
    """CPU seconds all processes of the machine have used so far (Linux ``/proc/stat``)."""
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:9]]
    except (OSError, ValueError):
        return None
    return (sum(v) - v[3] - v[4]) / os.sysconf("SC_CLK_TCK")


def _own_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _wait_quiet(budget_s: float, window_s: float = 0.3, idle: float = 0.9) -> float:
    """Wait until the machine's other processes used < ``1 - idle`` of its cores over
    ``window_s``; at most ``budget_s``. Returns the seconds waited (0 without /proc/stat)."""
    t0 = time.perf_counter()
    cores = os.cpu_count() or 1
    while time.perf_counter() - t0 < budget_s:
        b0, o0 = _busy_s(), _own_cpu_s()
        if b0 is None:
            return 0.0
        time.sleep(window_s)
        b1, o1 = _busy_s(), _own_cpu_s()
        if (b1 - b0) - (o1 - o0) < (1 - idle) * cores * window_s:
            break
    return time.perf_counter() - t0


def batch_scaling(
    model,
    red,
    dt: float,
    settle: float,
    duration: float,
    workers: int,
    repeats: int,
    quiet_wait: float,
) -> None:
    """A batch of 2 runs at the default chunk size on 1 and on ``workers`` workers.

    ``repeats`` alternating pairs (1 then ``workers`` workers, then the other way round), so
    slow drifts of the machine hit both sides alike; best and median of each side and the median
    of the paired ratios are printed. In the same pairs, the bare compiled kernel on the same two
    runs, one after another and on two plain threads (no gearte scheduling, no per-run set-up):
    the machine's own ceiling for this work. Inside the batches, each chunk's thread CPU is split
    into the kernel call and the rest (its set-up, which holds the GIL), and the other
    processes' CPU during the repeats (``/proc/stat`` minus this process) shows how quiet the
    machine was. Before each pair it waits until the other processes leave the cores idle
    (``_wait_quiet``), ``quiet_wait`` seconds at most in all; pairs during which the others
    used under 20 ms of CPU are also summarised on their own.
    """
    import threading
    from statistics import median

    import gearte.runners.rv_dynamics_sim as sim
    import gearte.solvers.ode as ode
    from gearte.execution import spawn_generators
    from gearte.runners.rv_dynamics_sim import draw_errors

    kw = dict(seed=1, duration_s=duration, settle_s=settle, dt=dt)
    kw["tolerances"] = batch_tolerances(red)

    # chunk and kernel timers: thread CPU of every chunk and of its kernel call
    log: list[tuple[float, float, float]] = []  # (chunk CPU, kernel CPU, kernel start) per chunk
    local = threading.local()
    inner_chunk, inner_kernels = sim._batch_chunk, ode.kernels

    def timed_chunk(task, shared):
        local.kernel, local.start = 0.0, 0.0
        c0 = time.thread_time()
        out = inner_chunk(task, shared)
        log.append((time.thread_time() - c0, local.kernel, local.start))
        return out

    def timed_kernels(rhs, output, key=""):
        rk4, dp = inner_kernels(rhs, output, key)

        def rk4_timed(*args):
            local.start = time.perf_counter()
            c0 = time.thread_time()
            res = rk4(*args)
            local.kernel += time.thread_time() - c0
            return res

        return rk4_timed, dp

    # the bare kernel on the batch's own two realisations (same draws as its two chunks)
    system = ode_system(model)
    rk4, _ = ode.kernels(system.rhs, system.output, system.key)
    n_steps = max(1, int(np.ceil((settle + duration) / dt - 1e-9)))
    h = (settle + duration) / n_steps
    settle_steps = int(round(settle / h))
    jobs = []
    for g in spawn_generators(kw["seed"], 2):
        err = draw_errors(g, kw["tolerances"], model.params.crank_count, model.params.disc_count)
        q0 = model.with_errors(err).static_equilibrium(0.0)
        jobs.append((np.concatenate([q0, np.zeros_like(q0)]), model.kernel_args(err)))
    no_idx, no_trace, no_rec = np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 0))

    def bare(i: int, cpu: list, barrier=None) -> None:
        y0, args = jobs[i]
        if barrier is not None:
            barrier.wait()
        c0 = time.thread_time()
        rk4(
            y0,
            0.0,
            h,
            n_steps,
            args,
            settle_steps,
            0,
            no_idx,
            no_trace,
            no_rec,
            system.work_size,
            np.empty((0, 2)),
        )
        cpu[i] = time.thread_time() - c0

    def bare_run(w: int) -> tuple[float, list]:
        cpu = [0.0, 0.0]
        t0 = time.perf_counter()
        if w == 1:
            bare(0, cpu)
            bare(1, cpu)
        else:
            barrier = threading.Barrier(2)
            ts = [threading.Thread(target=bare, args=(i, cpu, barrier)) for i in range(2)]
            for t in ts:
                t.start()
            for t in ts:
                t.join()
        return time.perf_counter() - t0, cpu

    sim._batch_chunk, ode.kernels = timed_chunk, timed_kernels
    try:
        rows = {w: dte_batch(model, 2, workers=w, **kw)["rows"] for w in (1, workers)}  # warm
        bare_run(1), bare_run(2)
        res: dict = {1: [], workers: []}
        ref: dict = {1: [], 2: []}
        foreign: list[float] = []  # other processes' CPU during each pair's two batches [s]
        waited = 0.0
        for rep in range(repeats):
            if waited < quiet_wait:
                waited += _wait_quiet(quiet_wait - waited)
            b0, o0 = _busy_s(), _own_cpu_s()
            for w in (1, workers) if rep % 2 == 0 else (workers, 1):
                log.clear()
                c0, t0 = time.process_time(), time.perf_counter()
                r = dte_batch(model, 2, workers=w, **kw)
                wall, cpu = time.perf_counter() - t0, time.process_time() - c0
                if not np.array_equal(r["rows"], rows[1]):
                    raise SystemExit(f"batch rows differ between runs ({w} workers)")
                starts = sorted(x[2] for x in log)
                res[w].append((wall, cpu, list(log), starts[-1] - starts[0]))
            b1, o1 = _busy_s(), _own_cpu_s()
            if b0 is not None and b1 is not None:
                foreign.append(max(0.0, (b1 - b0) - (o1 - o0)))
            for w in (1, 2) if rep % 2 == 0 else (2, 1):
                ref[w].append(bare_run(w))
    finally:
        sim._batch_chunk, ode.kernels = inner_chunk, inner_kernels
    same = np.array_equal(rows[1], rows[workers])

    def side(w):
        walls = [x[0] for x in res[w]]
        cpus = [x[1] for x in res[w]]
        chunk = [c for x in res[w] for c, _, _ in x[2]]
        kern = [k for x in res[w] for _, k, _ in x[2]]
        return walls, cpus, median(chunk), median(kern)

    w1, c1, ch1, k1 = side(1)
    w2, c2, ch2, k2 = side(workers)
    ratios = [a[0] / b[0] for a, b in zip(res[1], res[workers], strict=True)]
    best, med = min(w1) / min(w2), median(ratios)
    stagger = median(x[3] for x in res[workers])
    bare_ratios = [a[0] / b[0] for a, b in zip(ref[1], ref[2], strict=True)]
    bare_best = min(x[0] for x in ref[1]) / min(x[0] for x in ref[2])
    bk1 = median(c for x in ref[1] for c in x[1])
    bk2 = median(c for x in ref[2] for c in x[1])
    load = os.getloadavg()
    quiet = (
        f"other processes' CPU during a pair: median {median(foreign) * 1e3:.0f} ms, max "
        f"{max(foreign) * 1e3:.0f} ms (waited {waited:.1f} s for quiet)"
        if foreign
        else "other processes' CPU: n/a"
    )
    calm = [i for i, f in enumerate(foreign) if f < 0.02]
    ms = 1e3
    print(
        f"batch of 2 runs ({duration:g} s + {settle:g} s simulated each), default chunks, "
        f"{repeats} alternating pairs; load average {load[0]:.1f}; {quiet}; rows identical for 1 "
        f"and {workers} workers: {same}"
    )
    print(
        f"  1 worker : wall best {min(w1) * ms:.1f} ms, median {median(w1) * ms:.1f} ms; CPU "
        f"median {median(c1) * ms:.1f} ms; per run: chunk {ch1 * ms:.1f} ms CPU, of it kernel "
        f"{k1 * ms:.1f} ms"
    )
    print(
        f"  {workers} workers: wall best {min(w2) * ms:.1f} ms, median {median(w2) * ms:.1f} ms; "
        f"CPU median {median(c2) * ms:.1f} ms; per run: chunk {ch2 * ms:.1f} ms CPU, of it kernel "
        f"{k2 * ms:.1f} ms (×{k2 / k1:.2f} of 1 worker); second kernel starts {stagger * ms:.1f} "
        f"ms after the first"
    )
    print(
        f"  bare compiled kernel, same 2 runs, 2 plain threads vs one after another (the "
        f"machine's ceiling): best {bare_best:.2f}×, median of pairs {median(bare_ratios):.2f}×; "
        f"kernel CPU per run {bk1 * ms:.1f} ms alone, {bk2 * ms:.1f} ms two at once "
        f"(×{bk2 / bk1:.2f})"
    )
    if calm:
        cw1 = [res[1][i][0] for i in calm]
        cw2 = [res[workers][i][0] for i in calm]
        print(
            f"  the {len(calm)} pairs during which other processes used < 20 ms CPU: best "
            f"{min(cw1) / min(cw2):.2f}×, median of pairs {median(ratios[i] for i in calm):.2f}×"
        )
    # The verdict reads the median of the paired ratios: the two batches of a pair run back to
    # back, in the same state of the machine. The best of each side may pair a 1-worker sample
    # from a fast moment with 2-worker samples from a slow one (the bare kernel shows the same
    # spread), so it is printed beside it, not used for the verdict.
    if foreign:
        busy = median(foreign) >= 0.02
        note = f" (other processes busy: median {median(foreign) * 1e3:.0f} ms CPU per pair)"
    else:
        busy = load[0] >= 1.0
        note = f" (load average {load[0]:.1f})"
    print(
        f"goal batch of 2 on {workers} workers ≥ 1.6× 1 worker (wall): median of {repeats} "
        f"paired ratios {med:.2f}× — {'met' if med >= 1.6 else 'NOT met'}; best of each side "
        f"{best:.2f}× (bare kernel: median {median(bare_ratios):.2f}×, best {bare_best:.2f}×)"
        f"{note if busy else ''}"
    )
    # Amdahl from CPU times: what cannot overlap is the parent's work outside the chunks and
    # each chunk's set-up outside its kernel (Python: it holds the GIL, so the two chunks'
    # set-ups run one after the other); the kernels run in parallel
    # per 1-worker batch: its CPU minus its kernels' (serial), minus its chunks' (the parent)
    serial = median(x[1] - sum(k for _, k, _ in x[2]) for x in res[1])
    parent = median(x[1] - sum(c for c, _, _ in x[2]) for x in res[1])
    setup = median(c - k for x in res[1] for c, k, _ in x[2])
    print(
        f"  CPU split (1 worker, medians): kernel {k1 * ms:.1f} ms per run; outside the kernels "
        f"{serial * ms:.1f} ms per batch (set-up {setup * ms:.2f} ms per run, the parent "
        f"{parent * ms:.1f} ms) → on 2 idle cores at most "
        f"{(serial + 2 * k1) / (serial + k1):.2f}× (Amdahl)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline-span", type=float, default=0.02, help="simulated s for solve_ivp")
    ap.add_argument("--full-baseline", action="store_true", help="run solve_ivp on the full span")
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--batch-duration", type=float, default=1.0, help="simulated s/realisation")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=15, help="batch of 2: alternating pairs")
    ap.add_argument(
        "--quiet-wait", type=float, default=20.0, help="batch of 2: most s to wait for idle cores"
    )
    ap.add_argument("--only", default="speed,batch,memory", help="parts to run (comma list)")
    ap.add_argument("--record-dt", type=float, default=1e-4, help="memory: recording interval")
    ap.add_argument("--report", action="store_true", help="memory: also write the report")
    ap.add_argument("--memory-child", type=float, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.memory_child is not None:
        _memory_child(a.memory_child, a.record_dt, a.report)
        return
    parts = set(a.only.split(","))

    model, red = load_dynamic_model("li2023_rv_errors")  # Li 2023 Tables 1-3, mean k_cr
    dt = default_step(model)
    settle = 0.1
    if "speed" in parts:
        speed(model, red, a)
    if "batch" in parts:
        batch(model, red, dt, settle, a)
        batch_scaling(model, red, dt, settle, a.batch_duration, a.workers, a.repeats, a.quiet_wait)
        batch_scaling(model, red, dt, settle, 0.5, a.workers, a.repeats, a.quiet_wait)
    if "memory" in parts:
        memory(a.record_dt, a.report)


def speed(model, red, a) -> None:
    """Parts 1-3 and 5: the compiled integrator against its baselines."""
    system = ode_system(model)
    dt = default_step(model)
    q0 = model.static_equilibrium(0.0)
    y0 = np.concatenate([q0, np.zeros_like(q0)])
    settle, span = 0.1, 4.84
    print(f"model: {model.n_dof} DOF, RK4 step {dt:.3g} s (0.85 × stability limit)")

    # compile / cache load, reported separately
    t0 = time.perf_counter()
    rk4, _ = kernels(system.rhs, system.output, system.key)
    integrate(system, y0, (0.0, 10 * dt), method="rk4", dt=dt)
    t_compile = time.perf_counter() - t0
    hits = sum(rk4.stats.cache_hits.values())
    how = "cache hit" if hits else "compiled"
    print(f"kernel compile/cache load      : {t_compile:8.3f} s ({how})")

    # right-hand side alone
    args = system.args
    out = np.empty_like(y0)
    work = np.full(RHS_WORK_SIZE, np.nan)
    _rhs_loop(10, y0.copy(), args, out, work)
    n = 200_000
    t0 = time.perf_counter()
    _rhs_loop(n, y0.copy(), args, out, work)
    t_rhs = (time.perf_counter() - t0) / n
    yy = y0.copy()
    t0 = time.perf_counter()
    for _ in range(200):
        model.rhs_numpy(0.01, yy)
    t_rhs_py = (time.perf_counter() - t0) / 200
    print(f"rhs compiled, new t every call : {t_rhs * 1e6:8.3f} µs (goal ≤ 2 µs)")
    print(f"rhs plain Python (element loop): {t_rhs_py * 1e6:8.1f} µs")

    # compiled path, full revolution
    t0 = time.perf_counter()
    r = integrate(system, y0, (0.0, settle + span), method="rk4", dt=dt, t_settle=settle)
    t_fast = time.perf_counter() - t0
    p2p = r.stats["peak_to_peak"] * ARCSEC_PER_RAD
    print(f"RK4 cost per rhs evaluation    : {t_fast / r.n_rhs * 1e6:8.3f} µs (with the memo)")
    print(
        f"compiled RK4, {span + settle:.2f} s simulated : {t_fast:8.3f} s "
        f"(goal ≤ 1 s), DTE p2p {p2p:.3f}″ (paper 17.25″)"
    )

    # strong baselines: hand-written numba RK4, solve_ivp on the compiled rhs
    n_steps = int(round((settle + span) / dt))
    settle_steps = int(round(settle / dt))
    _rk4_hand(y0, 0.0, dt, 10, 0, args, RHS_WORK_SIZE)  # compile
    c0 = time.process_time()
    p2p_hand = _rk4_hand(y0, 0.0, dt, n_steps, settle_steps, args, RHS_WORK_SIZE)
    c_hand = time.process_time() - c0
    c0 = time.process_time()
    integrate(system, y0, (0.0, settle + span), method="rk4", dt=dt, t_settle=settle)
    c_fast = time.process_time() - c0
    print(
        f"hand-written numba RK4, same rhs/step: {c_hand:8.3f} s CPU (gearte {c_fast:.3f} s CPU:"
        f" {c_fast / c_hand:.2f}× of it, goal ≤ 1.5×), DTE p2p {p2p_hand * ARCSEC_PER_RAD:.3f}″"
    )
    verdict = "met" if c_fast / c_hand <= 1.5 else "NOT met"
    print(
        f"goal gearte RK4 ≤ 1.5× hand-written numba RK4 (CPU): {c_fast / c_hand:.2f}× — {verdict}"
    )
    from scipy.integrate import solve_ivp

    w = np.full(RHS_WORK_SIZE, np.nan)

    def f_numba(t, y):
        d = np.empty_like(y)
        rv_rhs(t, y, args, d, w)
        return d

    for meth in ("RK45", "DOP853"):
        c0 = time.process_time()
        sol = solve_ivp(f_numba, (0.0, a.baseline_span), y0, method=meth, rtol=1e-6, atol=1e-10)
        c_ivp = (time.process_time() - c0) * (settle + span) / a.baseline_span
        print(
            f"solve_ivp {meth:6s} on the numba rhs : {c_ivp:8.1f} s CPU for the full span (scaled "
            f"from {a.baseline_span:g} s, {sol.nfev} rhs calls): gearte {c_ivp / c_fast:.0f}×"
        )

    # baseline: solve_ivp on the plain-Python rhs
    b_total = span + settle if a.full_baseline else a.baseline_span
    b_settle = settle if a.full_baseline else 0.25 * b_total
    t0 = time.perf_counter()
    rb = integrate(
        system,
        y0,
        (0.0, b_total),
        method="scipy",
        rtol=1e-6,
        atol=1e-10,
        t_settle=b_settle,
        record_dt=dt,
    )
    t_base = time.perf_counter() - t0
    rc = integrate(system, y0, (0.0, b_total), method="rk4", dt=dt, t_settle=b_settle)
    scale = (span + settle) / b_total
    t_base_full = t_base * scale
    print(
        f"solve_ivp RK45 plain rhs, {b_total:.3g} s: {t_base:8.2f} s, {rb.n_rhs} rhs calls; DTE "
        f"p2p {rb.stats['peak_to_peak'] * ARCSEC_PER_RAD:.4f}″ vs compiled RK4 "
        f"{rc.stats['peak_to_peak'] * ARCSEC_PER_RAD:.4f}″ on the same span"
    )
    kind = "measured" if a.full_baseline else f"scaled ×{scale:.1f} from the short span"
    print(f"baseline for the full span     : {t_base_full:8.1f} s ({kind})")
    print(f"speed-up compiled / baseline   : {t_base_full / t_fast:8.0f}× (goal ≥ 200×)")


def batch(model, red, dt: float, settle: float, a) -> None:
    """Part 4: ``--samples`` realisations, sequential against threads."""
    # batch of error realisations
    kw = dict(seed=1, duration_s=a.batch_duration, settle_s=settle, chunk_size=4, dt=dt)
    kw["tolerances"] = batch_tolerances(red)
    dte_batch(model, 2, workers=1, **kw)  # warm the threads' first call
    r1 = dte_batch(model, a.samples, workers=1, **kw)
    r2 = dte_batch(model, a.samples, workers=a.workers, **kw)
    same = np.array_equal(r1["rows"], r2["rows"])
    diff = float(np.max(np.abs(r1["rows"] - r2["rows"])))
    print(f"batch rows identical for 1 and {a.workers} workers: {same} (max diff {diff:.3g})")
    for lab, rr in (("one after another", r1), (f"{a.workers} threads", r2)):
        print(
            f"batch {a.samples} realisations, {lab:17s}: {rr['wall_s']:7.2f} s wall, "
            f"{rr['simulated_s'] / rr['wall_s']:7.1f} sim-s/s (goal ≥ 50 aggregate)"
        )
    print(f"batch speed-up threads / sequential: {r1['wall_s'] / r2['wall_s']:.2f}×")
    print(
        f"DTE p2p over realisations: mean {r2['peak_to_peak_mean']:.2f}″, sd "
        f"{r2['peak_to_peak_sd']:.2f}″, max {r2['peak_to_peak_max']:.2f}″"
    )


if __name__ == "__main__":
    main()
