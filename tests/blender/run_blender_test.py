#!/usr/bin/env python3
"""A real renderer displacing with dispex's UV-space maps (ctest label `blender`).

For each case: a sculpt (generated with a known displacement, or a real pair), `dispex extract
--uv-maps`, Blender 3.4 headless displacing the base with the UDIM tiles (tests/blender/
displace.py: Subdivision Surface with limit surface and UV Smooth None, Displace along the
normal, mid level 0, strength 1; an object-space vector map through "RGB to XYZ" in local
space), and `dispex verify --displaced` measuring Blender's mesh
against the sculpt both ways: the 99th percentile must be within P99_TOLERANCES x the map's
tolerance. Wrong maps (zero, rows flipped in v, u and v transposed, tiles swapped) must fail
the same bound; the add-on (blender/) is driven the same way.
Exits 77 (skipped) when Blender is not installed.

    run_blender_test.py --dispex BUILD/tools/dispex --data tests/data --work DIR [--blender B]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

P99_TOLERANCES = 2.0
HERE = os.path.dirname(os.path.abspath(__file__))

# name, base (under tests/data), sculpt: (levels, pattern, amplitude) or a real sculpt's path,
# UV tile resolution, Blender's subdivision levels, wrong maps to try, and the map's kind:
# "scalar" (Displace along the normal) or "object" (an object-space vector map, Displace "RGB to
# XYZ" in local space).
CASES = [
    ("spot", "meshes/keenan_spot/spot_control_mesh.obj", (3, "detail", 0.005), 512, 4,
     ["zero"], "scalar"),
    ("box_six_tiles", "uv_maps/udim_box.obj", (4, "detail", 0.02), 256, 5,
     ["zero", "flip-v", "transpose", "swap-tiles"], "scalar"),
    ("wavy_plane_ngons", "image_pattern/wavy_plane.obj", (4, "smooth", 0.05), 256, 5, ["zero"],
     "scalar"),
    ("spot_real_pair", "meshes/keenan_spot/spot_control_mesh.obj",
     "meshes/keenan_spot/spot_quadrangulated.obj", 512, 4, ["zero"], "scalar"),
    # Bumps sheared until they fold over themselves: no scalar map holds them.
    ("box_vector", "uv_maps/udim_box.obj", (4, "overhang", 0.02), 512, 5,
     ["zero", "swap-rg", "flip-v"], "object"),
    ("wavy_vector_ngons", "image_pattern/wavy_plane.obj", (4, "overhang", 0.05), 1024, 5,
     ["zero", "swap-rg"], "object"),
    ("spot_real_vector", "meshes/keenan_spot/spot_control_mesh.obj",
     "meshes/keenan_spot/spot_quadrangulated.obj", 512, 4, ["zero", "swap-rg"], "object"),
]


def run(cmd, **kw):
    return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


def must(cmd):
    r = run(cmd)
    if r.returncode != 0:
        sys.exit("FAILED: %s\n%s" % (" ".join(cmd), r.stdout))
    return r.stdout


def addon_case(a, blender, vector):
    """The add-on (blender/dispex_displacement.py) on the box of six tiles: Extract
    Displacement (a scalar map, or with `vector` an object-space vector map of a sculpt that
    folds over), then the base with the modifiers it set up against the sculpt."""
    label = "addon_vector" if vector else "addon"
    work = os.path.join(a.work, label)
    os.makedirs(work)
    base = os.path.join(a.data, "uv_maps/udim_box.obj")
    sculpt = os.path.join(work, "sculpt.obj")
    must([a.dispex, "make-sculpt", base, "--levels", "4", "--pattern",
          "overhang" if vector else "detail", "--amplitude", "0.02", "-o", sculpt, "-q"])
    out = os.path.join(work, "blender_addon.obj")
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(os.path.abspath(a.dispex)) + os.pathsep + env.get("PATH", "")
    r = run([blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "addon_test.py"),
             "--", os.path.join(HERE, "..", "..", "blender"), base, sculpt,
             os.path.join(work, "maps"), out] + (["vector"] if vector else []), env=env)
    if r.returncode != 0 or not os.path.exists(out):
        return ["%s: Blender failed:\n%s" % (label, r.stdout[-3000:])]
    info = json.loads(must([a.dispex, "info", os.path.join(work, "maps", "base.<UDIM>.exr"),
                            "--json"]))
    tolerance = float(info["attributes"]["dispex:tolerance"])
    verify_json = os.path.join(work, "verify.json")
    v = run([a.dispex, "verify", "--displaced", out, sculpt, "--max-p99",
             repr(P99_TOLERANCES * tolerance), "--report", verify_json, "-q"])
    if v.returncode not in (0, 3):
        return ["%s: verify failed:\n%s" % (label, v.stdout)]
    m = json.load(open(verify_json))
    p99s = (m["map_to_sculpt"]["p99"], m["sculpt_to_map"]["p99"])
    print("%-18s %-10s %10.4g %10.4g %10.4g  %s (%.2f / %.2f tolerances, %d tiles)" % (
        label + " (box)", "none", tolerance, p99s[0], p99s[1],
        "ok" if v.returncode == 0 else "WRONG", p99s[0] / tolerance, p99s[1] / tolerance,
        len(info["tiles"])))
    if v.returncode != 0 or len(info["tiles"]) != 6:
        return ["%s: the add-on's result fails the bound of %g tolerances" % (label,
                                                                              P99_TOLERANCES)]
    return []


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dispex", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--only", default="", help="run only the case of this name")
    a = ap.parse_args()
    blender = shutil.which(a.blender)
    if not blender:
        print("SKIPPED: %s not found; install it with DISPEX_WITH_BLENDER=1 scripts/install-deps.sh"
              % a.blender)
        return 77
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    failures = []
    print("%-18s %-10s %10s %10s %10s  %s" % ("case", "map", "tolerance", "p99 d->s", "p99 s->d",
                                              "result"))
    for name, base, sculpt, resolution, levels, wrongs, kind in CASES:
        if a.only and name != a.only:
            continue
        work = os.path.join(a.work, name)
        os.makedirs(work)
        base = os.path.join(a.data, base)
        if isinstance(sculpt, tuple):
            sculpt_path = os.path.join(work, "sculpt.obj")
            must([a.dispex, "make-sculpt", base, "--levels", str(sculpt[0]), "--pattern",
                  sculpt[1], "--amplitude", str(sculpt[2]), "-o", sculpt_path, "-q"])
        else:
            sculpt_path = os.path.join(a.data, sculpt)
        report_path = os.path.join(work, "report.json")
        must([a.dispex, "extract", base, sculpt_path, "-o", os.path.join(work, name + ".ptx"),
              "--uv-maps", os.path.join(work, "uv"), "--uv-resolution", str(resolution),
              "--report", report_path, "-q"] + ([] if kind == "scalar" else ["--vector", kind]))
        report = json.load(open(report_path))
        tolerance = report["statistics"]["tolerance"]
        pattern = os.path.join(work, "uv", name + ".<UDIM>.exr")
        for wrong in ["none"] + wrongs:
            out = os.path.join(work, "blender_%s.obj" % wrong)
            cmd = [blender, "-b", "--factory-startup", "--python",
                   os.path.join(HERE, "displace.py"), "--", base, pattern, out, "--levels",
                   str(levels), "--direction", "normal" if kind == "scalar" else "rgb"]
            if wrong != "none":
                cmd += ["--wrong", wrong, "--work", os.path.join(work, "wrong_" + wrong)]
            r = run(cmd)
            if r.returncode != 0 or not os.path.exists(out):
                failures.append("%s/%s: Blender failed:\n%s" % (name, wrong, r.stdout[-3000:]))
                continue
            verify_json = os.path.join(work, "verify_%s.json" % wrong)
            v = run([a.dispex, "verify", "--displaced", out, sculpt_path, "--max-p99",
                     repr(P99_TOLERANCES * tolerance), "--report", verify_json, "-q"])
            if v.returncode not in (0, 3):
                failures.append("%s/%s: verify failed:\n%s" % (name, wrong, v.stdout))
                continue
            m = json.load(open(verify_json))
            p99s = (m["map_to_sculpt"]["p99"], m["sculpt_to_map"]["p99"])
            passed = v.returncode == 0
            expected = wrong == "none"
            verdict = "ok" if passed == expected else "WRONG"
            print("%-18s %-10s %10.4g %10.4g %10.4g  %s (%s, %.2f / %.2f tolerances)" % (
                name, wrong, tolerance, p99s[0], p99s[1], verdict,
                "passes" if passed else "fails", p99s[0] / tolerance, p99s[1] / tolerance))
            if passed != expected:
                failures.append("%s/%s: %s the bound of %g tolerances" % (
                    name, wrong, "passes" if passed else "fails", P99_TOLERANCES))
    for vector in (False, True):
        if not a.only or a.only == ("addon_vector" if vector else "addon"):
            failures += addon_case(a, blender, vector)
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
