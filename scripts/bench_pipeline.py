"""Runs every case of a bench manifest (scripts/bench_scenes.py), each in its own process, and
writes their results as one JSON document:

    /usr/bin/python3.11 scripts/bench_pipeline.py OUT/manifest.json RESULT.json [--timeout S] [NAME...]

A case's peak memory is the child's maximum resident set size as the kernel reports it to the
parent (os.wait4), so it covers the Python interpreter, numpy, the mesh and the solver. A case that
fails or runs past --timeout is recorded with its error and the others still run; the exit status
is 1 if any case failed.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "addon"))
sys.path.insert(0, HERE)
from bench_case import NO_SOLVER_STATUS  # noqa: E402

NO_SOLVER = "no_solver"  # a case's `cause` when its process could not load the solver module


def run_case(case, folder, timeout, budget):
    scene = os.path.join(folder, case["scene"])
    cmd = [sys.executable, os.path.join(HERE, "bench_case.py"), scene, "--budget", str(budget)]
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        child = subprocess.Popen(cmd, stdout=out, stderr=err)
        deadline = start + timeout
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() > deadline:
                child.kill()
                pid, status, usage = os.wait4(child.pid, 0)
                child.returncode = -9
                return {"error": f"stopped after {timeout:.0f} s (--timeout)", "seconds": time.perf_counter() - start}
            time.sleep(0.02)
        child.returncode = os.waitstatus_to_exitcode(status)
        seconds = time.perf_counter() - start
        out.seek(0)
        err.seek(0)
        text, errors = out.read(), err.read()
    if child.returncode != 0:
        tail = errors.strip().splitlines()[-1:] or ["no message"]
        failure = {"error": f"exit status {child.returncode}: {tail[0]}", "seconds": seconds}
        if child.returncode == NO_SOLVER_STATUS:
            failure["cause"] = NO_SOLVER
        return failure
    result = json.loads(text)
    result["process_seconds"] = seconds
    result["peak_rss_kib"] = usage.ru_maxrss  # KiB on Linux
    return result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("manifest")
    parser.add_argument("result")
    parser.add_argument("--timeout", type=float, default=240.0, help="seconds per case (default 240)")
    parser.add_argument("--budget", type=float, default=12.0, help="seconds of repeated solving per case")
    parser.add_argument("names", nargs="*", help="only the cases whose names contain one of these")
    args = parser.parse_args(argv)
    folder = os.path.dirname(os.path.abspath(args.manifest))
    with open(args.manifest) as f:
        cases = json.load(f)["cases"]
    results, failed = [], 0
    for case in cases:
        if args.names and not any(n in case["name"] for n in args.names):
            continue
        r = run_case(case, folder, args.timeout, args.budget)
        for _retry in range(6):  # the module was being rebuilt (another build in this tree): wait for it
            if r.get("cause") != NO_SOLVER:
                break
            print(f"wiresculpt: bench {case['name']}: the solver module is not loadable, retrying in 10 s",
                  file=sys.stderr, flush=True)
            time.sleep(10)
            r = run_case(case, folder, args.timeout, args.budget)
        entry = dict(case, **{k: v for k, v in r.items() if k not in ("scene", "cause")})
        entry["expected"] = {"P": case["P"], "C": case["C"]}
        if "error" in r:
            failed += 1
            entry["P"], entry["C"] = case["P"], case["C"]
            print(f"wiresculpt: bench {case['name']}: {r['error']}", file=sys.stderr, flush=True)
        else:
            st = r["stages"]
            line = ", ".join(f"{name} {s.get('seconds', s.get('wall_seconds', 0.0)):.3f} s" for name, s in st.items())
            print(f"wiresculpt: bench {case['name']}: P={r['P']} C={r['C']} longest {r['longest_wire']:.2f} m, "
                  f"{line}, {r['repeats']} runs, peak {r['peak_rss_kib'] / 1024:.0f} MiB "
                  f"({r['process_seconds']:.1f} s)", file=sys.stderr, flush=True)
        results.append(entry)
    from wiresculpt.core.files import write_atomic
    write_atomic(args.result, json.dumps({"cases": results}, indent=1) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
