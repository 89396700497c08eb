#!/usr/bin/env python3
"""A memory limit the kernel enforces, with no --max-memory given: under an address-space limit
(`ulimit -v`) below what one pass of a rays extraction maps, and, where this process may make
one, under a cgroup memory limit below its peak, `dispex extract` reads the limit, traces the
sculpt in parts (or, in the cgroup, builds the whole sculpt's BVH compact where the estimate
says that fits) and writes the map of the unlimited run, byte for byte. The controls: the same
run forced to one pass (--max-memory far above the limit) fails there -- so the limit is below
the one-pass need -- cleanly under the address-space limit (exit 1, no output), killed by the
kernel under the cgroup.
    memory_limit_test.py DISPEX SPOT_CAGE"""
import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time

dispex, cage = sys.argv[1], sys.argv[2]
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what, flush=True)
    if not condition:
        failures.append(what)


def extract(output, *flags, preexec=None, cgroup=None):
    """Runs an extraction (rays, two threads), polling its peak memory; (status, peaks, stderr)."""
    command = [dispex, "extract", cage, sculpt, "-o", output, "--method", "rays",
               "--search-distance", "0.5%", "--threads", "2", "-q", "--report", output + ".json",
               *flags]
    if cgroup:
        command = ["sh", "-c", f'echo $$ > "{cgroup}/cgroup.procs" && exec "$@"', "sh", *command]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True, preexec_fn=preexec)
    peaks = {"VmPeak": 0, "VmHWM": 0}
    while process.poll() is None:
        try:
            with open(f"/proc/{process.pid}/status") as status:
                for line in status:
                    key = line.split(":")[0]
                    if key in peaks:
                        peaks[key] = max(peaks[key], int(line.split()[1]) * 1024)
        except OSError:
            pass
        time.sleep(0.01)
    return process.returncode, peaks, process.stderr.read()


def report(output):
    with open(output + ".json") as f:
        return json.load(f)


def read(path):
    with open(path, "rb") as f:
        return f.read()


with tempfile.TemporaryDirectory(prefix="dispex_memory_limit_") as work:
    sculpt = os.path.join(work, "sculpt.ply")
    subprocess.run([dispex, "make-sculpt", cage, "--levels", "5", "--amplitude", "0.005", "-q",
                    "-o", sculpt], check=True)
    whole = os.path.join(work, "whole.ptx")
    status, peaks, err = extract(whole)
    check(status == 0 and report(whole)["plan"]["tracer"] == "whole sculpt",
          f"one pass without a limit ({err.strip()})")
    expected = read(whole)

    # The address-space limit: 95% of what the one pass mapped at its peak.
    limit = int(0.95 * peaks["VmPeak"])
    def address_space():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    parts = os.path.join(work, "parts_as.ptx")
    status, _, err = extract(parts, preexec=address_space)
    check(status == 0, f"under ulimit -v {limit >> 20} MiB the extraction runs ({err.strip()})")
    if status == 0:
        r = report(parts)
        check(r["plan"]["tracer"] == "in parts" and r["plan"]["memory"]["sculpt_parts"] >= 2,
              f"it traced the sculpt in parts ({r['plan']['memory']})")
        check(read(parts) == expected, "the map is byte-identical to the unlimited run's")
    forced = os.path.join(work, "forced_as.ptx")
    status, _, err = extract(forced, "--max-memory", "64G", preexec=address_space)
    check(status == 1 and not os.path.exists(forced) and "dispex:" in err,
          f"forced to one pass under the same limit it fails cleanly (exit {status}: "
          f"{err.strip()})")

    # The cgroup limit: 80% of the one pass's peak resident memory, in a cgroup of our own.
    v1 = v2 = None
    with open("/proc/self/cgroup") as f:
        for line in f:
            number, controllers, path = line.rstrip("\n").split(":", 2)
            if "memory" in controllers.split(","):
                v1 = path
            if number == "0" and not controllers:
                v2 = path
    candidates = []
    if v1 is not None:
        candidates.append(("/sys/fs/cgroup/memory" + v1, "memory.limit_in_bytes"))
    if v2 is not None:
        candidates.append(("/sys/fs/cgroup" + v2, "memory.max"))
    cgroup = None
    for parent, limit_file in candidates:
        path = os.path.join(parent, f"dispex-test-{os.getpid()}")
        try:
            os.mkdir(path)
            with open(os.path.join(path, limit_file), "w") as f:
                f.write(str(int(0.8 * peaks["VmHWM"])))
            cgroup = path
            break
        except OSError:
            try:
                os.rmdir(path)
            except OSError:
                pass
    if cgroup is None:
        print("note: no cgroup of our own can be made here (not root, or no memory controller); "
              "the address-space limit above is the test")
    else:
        try:
            parts = os.path.join(work, "parts_cg.ptx")
            status, _, err = extract(parts, cgroup=cgroup)
            check(status == 0, f"in a cgroup of {int(0.8 * peaks['VmHWM']) >> 20} MiB the "
                               f"extraction runs ({err.strip()})")
            if status == 0:
                plan = report(parts)["plan"]
                check(plan["tracer"] == "in parts" or plan["memory"]["compact_bvh"],
                      f"it built the BVH compact or traced in parts ({plan['memory']})")
                check(read(parts) == expected, "the map is byte-identical to the unlimited run's")
            forced = os.path.join(work, "forced_cg.ptx")
            status, _, err = extract(forced, "--max-memory", "64G", cgroup=cgroup)
            check(status != 0 and not os.path.exists(forced),
                  f"forced to one pass in the same cgroup it does not finish (status {status})")
        finally:
            os.rmdir(cgroup)

sys.exit(1 if failures else 0)
