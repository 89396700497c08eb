#!/usr/bin/env python3
"""A real renderer displacing with dispex's UV-space maps (ctest label `blender`).

For each case: a sculpt (generated with a known displacement, or a real pair), `dispex extract
--uv-maps`, Blender 3.4 headless displacing the base with the UDIM tiles (tests/blender/
displace.py: Subdivision Surface with limit surface and UV Smooth None, Displace along the
normal, mid level 0, strength 1; an object-space vector map through "RGB to XYZ" in local
space), and `dispex verify --displaced` measuring Blender's mesh against the sculpt both ways,
in units of the map's tolerance: the 99th percentile of the distances each way and their mean
both ways must be within BOUNDS. In the same Blender session the map is made wrong on purpose
(x0.8 and sign flipped on every case; zero, rows flipped in v, u and v transposed, tiles
swapped, x and y swapped where listed), and every wrong map must break a bound; the add-on
(blender/) is driven the same way, its Displace texture's image swapped for the wrong maps,
after its own checks (one-line errors, dispex's warnings in its reports, a cancel, a rerun
re-using its texture and image, no temporary folder left: addon_test.py). Exits 77 (skipped) when Blender is not installed.

    run_blender_test.py --dispex BUILD/tools/dispex --data tests/data --work DIR [--blender B]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

# Bounds on Blender's mesh against the sculpt, in tolerances of the map: the 99th percentile of
# the distances each way, and their mean both ways (the average of the two means). Measured,
# the map and the map x0.8 (the closest wrong map), mean both ways / p99 the larger way:
#   case               the map        x0.8          case                the map        x0.8
#   spot               0.111 / 1.12   0.471 / 1.44  box_vector          0.084 / 0.77   2.93 / 18
#   box_six_tiles      0.065 / 0.46   0.518 / 1.42  wavy_vector_ngons   0.052 / 0.73   3.76 / 17
#   wavy_plane_ngons   0.014 / 0.22   1.081 / 3.03  spot_real_vector    0.147 / 1.02   0.238 / 1.46
#   spot_real_pair     0.137 / 1.10   0.230 / 1.53  addon_vector (box)  0.128 / 1.07   2.94 / 18
#   addon (box)        0.065 / 0.46   0.518 / 1.42
# The p99 bound rejects every other wrong map (sign flipped 6.4 to 107, zero 3.6 to 66, v
# flipped, transposed, tiles or x and y swapped 4.2 to 90) but passes the map x0.8 on five
# cases. The mean bound lies between the most the map reaches (0.147, spot_real_vector) and the
# least the map x0.8 does (0.230, spot_real_pair), 1.25 times from each, and rejects every wrong
# map: the map x0.8 2.5 to 20 times over on the generated sculpts, 1.25 times on the real pairs
# (the quad mesh is within about a tolerance of the cage's limit surface: its whole displacement,
# the zero map, measures 0.66, and the map x0.8 is off by a fifth of that).
BOUNDS = {"p99": 2.0, "mean": 0.185}
# Every case's wrong maps include these: a map 20% off, the closest wrong map, and one of the
# wrong sign. They are the map scaled (2 |h| and 0.2 |h| off): the sign flipped one is up to 10
# times as far from the sculpt as the map x0.8 in the mean both ways (measured 3.0 to 10, less
# where the map's own error adds to both, or where the folded vector sculpts bring another part
# of the sculpt nearer the far one), which wrong maps that failed to load (Blender's missing
# texture, the same for both) would not be.
CONTROLS = ["x0.8", "sign"]
SIGN_OVER_FOUR_FIFTHS = (2.0, 15.0)
HERE = os.path.dirname(os.path.abspath(__file__))

# name, base (under tests/data), sculpt: (levels, pattern, amplitude) or a real sculpt's path,
# UV tile resolution, Blender's subdivision levels, more wrong maps to try, and the map's kind:
# "scalar" (Displace along the normal) or "object" (an object-space vector map, Displace "RGB to
# XYZ" in local space).
#
# The real pairs are measured against the facets of a coarse quad mesh (the cage refined twice,
# its vertices the level-2 control points, off the limit surface): the map that follows the
# facets is the one to hold them, so they extract with --method mapping. The default
# (interpolate: the vertices exact, bilinear between them over the curved limit surface) is
# farther from those facets there, a mean of 0.24 tolerances both ways against 0.14
# (docs/ACCURACY.md, "Interpolated vertex displacements").
REAL_PAIR_METHOD = ["--method", "mapping"]
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


def measure(a, name, wrong, mesh, sculpt, tolerance, work, means):
    """Blender's mesh against the sculpt both ways: [] when the verdict is the one expected of
    the map (within every bound for the map itself, beyond one for a wrong map), else the
    failure. `means` collects the mean both ways by wrong map."""
    verify_json = os.path.join(work, "verify_%s.json" % wrong)
    v = run([a.dispex, "verify", "--displaced", mesh, sculpt, "--max-p99",
             repr(BOUNDS["p99"] * tolerance), "--report", verify_json, "-q"])
    if v.returncode not in (0, 3):
        return ["%s/%s: verify failed:\n%s" % (name, wrong, v.stdout)]
    m = json.load(open(verify_json))
    ds, sd = m["map_to_sculpt"], m["sculpt_to_map"]
    p99 = max(ds["p99"], sd["p99"]) / tolerance
    mean = (ds["mean"] + sd["mean"]) / 2 / tolerance
    means[wrong] = mean
    broken = (["p99 %.2f > %g" % (p99, BOUNDS["p99"])] if p99 > BOUNDS["p99"] else []) + (
        ["mean %.3f > %g" % (mean, BOUNDS["mean"])] if mean > BOUNDS["mean"] else [])
    if (v.returncode == 3) != (p99 > BOUNDS["p99"]):
        return ["%s/%s: verify's --max-p99 verdict (exit %d) disagrees with its report" % (
            name, wrong, v.returncode)]
    expected = wrong == "none"
    verdict = "ok" if (not broken) == expected else "WRONG"
    print("%-18s %-10s %10.4g %6.2f %6.2f %6.3f %6.3f %6.3f  %s (%s)" % (
        name, wrong, tolerance, ds["p99"] / tolerance, sd["p99"] / tolerance,
        ds["mean"] / tolerance, sd["mean"] / tolerance, mean, verdict,
        "; ".join(broken) if broken else "within the bounds"))
    if (not broken) != expected:
        return ["%s/%s: %s" % (name, wrong, "; ".join(broken) if broken else
                               "a wrong map within every bound")]
    return []


def controls_scaled(name, means):
    """The sign flipped map against the map x0.8 (SIGN_OVER_FOUR_FIFTHS)."""
    if "sign" not in means or "x0.8" not in means:
        return []
    ratio = means["sign"] / max(means["x0.8"], 1e-30)
    low, high = SIGN_OVER_FOUR_FIFTHS
    if not low <= ratio <= high:
        return ["%s: the map sign flipped is %.3g times as far as the map x0.8, not %g to %g: "
                "are they the map scaled?" % (name, ratio, low, high)]
    return []


def addon_case(a, blender, vector):
    """The add-on (blender/dispex_displacement.py) on the box of six tiles: Extract
    Displacement (a scalar map, or with `vector` an object-space vector map of a sculpt that
    folds over), then the base with the modifiers it set up against the sculpt, and with the
    image of its Displace texture made wrong (CONTROLS). The scalar case first checks the
    add-on's errors, warnings, cancel and rerun (addon_test.py `checks`), so that the map
    measured is a rerun's."""
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
    # A temporary folder of its own: the add-on's (dispex_*) must all be gone after each step.
    env["TMPDIR"] = os.path.join(work, "tmp")
    os.makedirs(env["TMPDIR"])
    wrong_dir = os.path.join(work, "wrong")
    r = run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
             os.path.join(HERE, "addon_test.py"), "--", os.path.join(HERE, "..", "..", "blender"),
             base, sculpt, os.path.join(work, "maps"), out, ",".join(CONTROLS), wrong_dir]
            + (["vector"] if vector else ["checks"]), env=env)
    if r.returncode != 0 or not os.path.exists(out):
        return ["%s: Blender failed:\n%s" % (label, r.stdout[-3000:])]
    info = json.loads(must([a.dispex, "info", os.path.join(work, "maps", "base.<UDIM>.exr"),
                            "--json"]))
    if len(info["tiles"]) != 6:
        return ["%s: %d tiles, not 6" % (label, len(info["tiles"]))]
    tolerance = float(info["attributes"]["dispex:tolerance"])
    means = {}
    failures = measure(a, label + " (box)", "none", out, sculpt, tolerance, work, means)
    for wrong in CONTROLS:
        failures += measure(a, label + " (box)", wrong, os.path.join(wrong_dir, wrong + ".obj"),
                            sculpt, tolerance, work, means)
    return failures + controls_scaled(label, means)


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
    print("%-18s %-10s %10s %6s %6s %6s %6s %6s  %s" % (
        "case", "map", "tolerance", "p99", "p99", "mean", "mean", "mean", "result"))
    print("%-18s %-10s %10s %6s %6s %6s %6s %6s  (in tolerances; bounds: p99 %g, mean %g)" % (
        "", "", "", "d->s", "s->d", "d->s", "s->d", "both", BOUNDS["p99"], BOUNDS["mean"]))
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
              "--report", report_path, "-q"] + ([] if kind == "scalar" else ["--vector", kind]) +
             ([] if isinstance(sculpt, tuple) else REAL_PAIR_METHOD))
        report = json.load(open(report_path))
        tolerance = report["statistics"]["tolerance"]
        pattern = os.path.join(work, "uv", name + ".<UDIM>.exr")
        out = os.path.join(work, "blender_none.obj")
        wrong_dir = os.path.join(work, "wrong")
        # One Blender session: the map, then each wrong map (displace.py --wrong).
        r = run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                 os.path.join(HERE, "displace.py"), "--", base, pattern, out, "--levels",
                 str(levels), "--direction", "normal" if kind == "scalar" else "rgb",
                 "--wrong", ",".join(CONTROLS + wrongs), "--work", wrong_dir])
        if r.returncode != 0 or not os.path.exists(out):
            failures.append("%s: Blender failed:\n%s" % (name, r.stdout[-3000:]))
            continue
        means = {}
        failures += measure(a, name, "none", out, sculpt_path, tolerance, work, means)
        for wrong in CONTROLS + wrongs:
            failures += measure(a, name, wrong, os.path.join(wrong_dir, wrong + ".obj"),
                                sculpt_path, tolerance, work, means)
        failures += controls_scaled(name, means)
    for vector in (False, True):
        if not a.only or a.only == ("addon_vector" if vector else "addon"):
            failures += addon_case(a, blender, vector)
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
