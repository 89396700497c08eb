#!/usr/bin/env python3
"""scripts/check-skips.py on JUnit reports made here: allowed skips pass, any other skip (a
listed test skipping for another reason, an unlisted test, a report where nothing ran) fails."""
import os
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
CHECK = os.path.join(ROOT, "scripts", "check-skips.py")


def report(cases):
    body = "".join(
        f'<testcase name="{name}" status="{status}">'
        + ('<skipped message="SKIP_RETURN_CODE=77"/>' if status == "notrun" else "")
        + f"<system-out>{out}</system-out></testcase>" for name, status, out in cases)
    return f'<?xml version="1.0"?><testsuite tests="{len(cases)}">{body}</testsuite>'


def check(cases):
    with tempfile.NamedTemporaryFile("w", suffix=".xml", delete=False) as f:
        f.write(report(cases))
    try:
        return subprocess.run([sys.executable, CHECK, f.name], capture_output=True,
                              text=True).returncode
    finally:
        os.unlink(f.name)


ran = ("core_test.Status.Ok", "run", "")
isa_skip = ("trace_test[avx512].Trace.Hits", "notrun",
            "skipped: this CPU lacks the Embree ISA avx512 (DISPEX_EMBREE_ISA)")
cases = {
    "nothing skipped": ([ran], 0),
    "an allowed skip with its reason": ([ran, isa_skip], 0),
    "a listed test skipping for another reason": (
        [ran, ("trace_test[avx512].Trace.Hits", "notrun", "skipped: no reason we know")], 1),
    "an unlisted test skipping": ([ran, ("blender_displace", "notrun", "SKIPPED: blender")], 1),
    "a disabled test": ([ran, ("core_test.Status.DISABLED_X", "disabled", "")], 1),
    "nothing ran": ([isa_skip], 1),
}
failed = 0
for what, (junit, expected) in cases.items():
    got = check(junit)
    if got != expected:
        print(f"FAIL: {what}: exit {got}, expected {expected}")
        failed += 1
print(f"{len(cases) - failed} passed, {failed} failed")
sys.exit(1 if failed else 0)
