#!/usr/bin/env python3
"""Golden map hashes: the maps dispex writes for a fixed list of cases, held to stored hashes.

A safety net for refactors of the extraction pipeline: every case is a `dispex` command line
(or a few: shards then merge, a map then an incremental re-run) over the small test data in
tests/data/ and sculpts made from it by `dispex make-sculpt`; the sha256 of every file it
writes must equal the one stored in tests/golden/map_hashes.json. Some cases must also equal
another case byte for byte whatever is stored (a merge equals one extraction, an incremental
re-run a full one, one thread all of them): those checks hold under --update too.

  tests/golden/golden_maps.py [--dispex PATH] [--work DIR [--keep]] [--only REGEX] [--update]
                              [--embree-isa ISA] [--threads N] [--wrapper CMD] [--list]

--update rewrites the stored hashes (do it only for an intended change of the maps, and say
why in the commit). Exit 0: every hash as stored; 1: a hash differs, is missing or stale, or a
case failed; 2: bad usage; 77: --embree-isa names an ISA this CPU lacks (skip).
Standard library only (docs/DEVELOPING.md, "Golden map hashes").
"""
import argparse
import glob
import hashlib
import json
import os
import platform
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "tests", "data")
HASHES = os.path.join(HERE, "map_hashes.json")
EMBREE_ISAS = ["sse2", "sse4.2", "avx", "avx2", "avx512"]
WORK_MARK = ".golden_maps_work"  # marks a --work folder this script made (and may empty)

SPOT = "{data}/meshes/keenan_spot/spot_control_mesh.obj"  # n-gons (252 Ptex faces), UVs
CAR = "{data}/meshes/opensubdiv/catmark_car.obj"  # n-gons, boundaries, creases
TORUS = "{data}/meshes/opensubdiv/catmark_torus_creases0.obj"  # creases
TENT = "{data}/meshes/opensubdiv/catmark_tent.obj"  # boundaries, corners
HOLES = "{data}/meshes/opensubdiv/catmark_hole_test1.obj"  # hole faces
CHAIKIN = "{data}/meshes/dispex/chaikin_box.obj"  # Chaikin's crease rule
WAVY = "{data}/image_pattern/wavy_plane.obj"  # pentagons, triangles, UVs
BOX = "{data}/uv_maps/udim_box.obj"  # six UDIM tiles
# bench/run's assets (bench/make-assets) at the size of a test: the same cages, fewer levels.
HEAD = "{data}/meshes/keenan_blub/blub_control_mesh.obj"
BODY = "{data}/meshes/stanford_bunny/bun_zipper_quadriflow_1000.obj"
CAPE = "{data}/meshes/nefertiti/nefertiti_quadriflow_1000.obj"

# The sculpts, made once per run into {s}/: `make-sculpt` arguments, or a step of this script.
# Their contents (comment lines aside: they name the cage's path) are hashed too, so that a
# change of make-sculpt shows as such rather than as every map changing.
SCULPTS = {
    "spot_detail": f"make-sculpt {SPOT} --levels 3 --pattern detail --amplitude 0.005",
    "spot_flat": f"make-sculpt {SPOT} --levels 3 --pattern none",
    "spot_jittered": f"make-sculpt {SPOT} --layout jittered --density 8 --pattern detail "
                     "--amplitude 0.005",
    "spot_overhang": f"make-sculpt {SPOT} --levels 3 --pattern overhang --amplitude 0.005",
    "car_detail": f"make-sculpt {CAR} --levels 2 --pattern detail",
    "torus_jittered": f"make-sculpt {TORUS} --layout jittered --density 6 --pattern noise "
                      "--amplitude 0.02",
    "tent_smooth": f"make-sculpt {TENT} --levels 3 --pattern smooth --amplitude 0.008",
    "holes_ridges": f"make-sculpt {HOLES} --levels 3 --pattern ridges --amplitude 0.02",
    "chaikin_detail": f"make-sculpt {CHAIKIN} --levels 3 --pattern detail --amplitude 0.03",
    "wavy_image": f"make-sculpt {WAVY} --levels 3 "
                  "--pattern image:{data}/image_pattern/heights.png --amplitude 0.05",
    "box_detail": f"make-sculpt {BOX} --levels 3 --pattern detail --amplitude 0.02",
    "head": f"make-sculpt {HEAD} --levels 3 --pattern detail --amplitude 0.004",
    "body": f"make-sculpt {BODY} --levels 2 --pattern detail --amplitude 0.0003",
    "body_jittered": f"make-sculpt {BODY} --layout jittered --density 4 --pattern detail "
                     "--amplitude 0.0003",
    "cape": f"make-sculpt {CAPE} --levels 2 --pattern detail --amplitude 1.0",
    # Local edits of a sculpt, as an artist's (incremental re-extraction): @edit, below.
    "spot_detail_edited": "@edit spot_detail",
    "spot_overhang_edited": "@edit spot_overhang",
    # An asset of two shapes in the same place (tests/extract/shapes_test.cpp): @group, below.
    "asset_base": f"@group detail={SPOT} flat={SPOT}",
    "asset_sculpt": "@group flat={s}/spot_flat.obj detail={s}/spot_detail.obj",
}


def case(name, run, files=("map.ptx",), equal=None, rays=False):
    """`run`: command lines (dispex's arguments; {data}, {s}: the test data and the sculpts;
    `@copy A B` copies A to B). `files`: globs of the outputs hashed, in the case's folder.
    `equal`: a case whose files this one must equal byte for byte. `rays`: the case casts
    rays through Embree (run again under each ISA by --embree-isa)."""
    return {"name": name, "run": [run] if isinstance(run, str) else list(run),
            "files": list(files), "equal": equal, "rays": rays}


def extract(base, sculpt, options=""):
    return f"extract {base} {{s}}/{sculpt}.obj -o map.ptx {options}".strip()


SHARD_OPTIONS = "--method rays --search-distance 1%"
CASES = [
    # Scalar maps by each method, on a sculpt that is the base refined (Spot, n-gons).
    case("scalar_auto", extract(SPOT, "spot_detail")),  # auto: interpolate
    case("scalar_rays", extract(SPOT, "spot_detail", "--method rays"), rays=True),
    case("scalar_mapping", extract(SPOT, "spot_detail", "--method mapping"), rays=True),
    case("scalar_interpolate_half", extract(SPOT, "spot_detail",
                                            "--method interpolate --data-type half")),
    # Rays into a sculpt that is not the base refined (auto: rays), each watertight mode.
    case("jittered_filter", extract(SPOT, "spot_jittered"), rays=True),
    case("jittered_all", extract(SPOT, "spot_jittered", "--watertight all"), rays=True),
    case("jittered_off_outside_first",
         extract(SPOT, "spot_jittered", "--watertight off --ray-policy outside-first"), rays=True),
    # Resolution rules and options.
    case("fixed_resolution", extract(SPOT, "spot_detail", "--resolution-rule fixed "
                                     "--fixed-resolution 8x4 --method rays"), rays=True),
    case("nonzero_rule", extract(SPOT, "spot_jittered", "--resolution-rule nonzero "
                                 "--nonzero-threshold 0.0001 --compression-level 9"), rays=True),
    case("oversample_tolerance", extract(TORUS, "torus_jittered", "--oversample 16 "
                                         "--tolerance 0.002 --bvh-quality high"), rays=True),
    # Holes: rays that miss the sculpt (a search distance shorter than the detail).
    case("holes_fill", extract(SPOT, "spot_jittered", "--method rays --search-distance 0.004 "
                               "--max-miss-fraction 1 --holes fill"), rays=True),
    case("holes_zero", extract(SPOT, "spot_jittered", "--method rays --search-distance 0.004 "
                               "--max-miss-fraction 1 --holes zero"), rays=True),
    # Cage features: n-gons and boundaries, creases, hole faces, Chaikin creases, an image.
    case("car_rays_half_off", extract(CAR, "car_detail", "--method rays --data-type half "
                                      "--watertight off"), rays=True),
    case("tent_boundaries", extract(TENT, "tent_smooth", "--watertight all")),
    case("hole_faces", extract(HOLES, "holes_ridges", "--method mapping"), rays=True),
    case("chaikin_creases", extract(CHAIKIN, "chaikin_detail")),
    case("wavy_image_rays", extract(WAVY, "wavy_image", "--method rays --search-distance 2%"),
         rays=True),
    # bench/run's assets, small: head, cape (through the correspondence), body (both ways).
    case("bench_head", extract(HEAD, "head")),
    case("bench_cape", extract(CAPE, "cape")),
    case("bench_body_rays", extract(BODY, "body", "--method rays"), rays=True),
    case("bench_body_jittered", extract(BODY, "body_jittered"), rays=True),
    # Vector maps (docs/VECTOR.md): each space, the mapping method, watertight all, half.
    case("vector_object", extract(SPOT, "spot_overhang", "--vector object")),
    case("vector_tangent_all", extract(SPOT, "spot_detail", "--vector tangent --watertight all")),
    case("vector_parametric_half", extract(SPOT, "spot_overhang", "--vector parametric "
                                           "--data-type half")),
    case("vector_object_mapping_car", extract(CAR, "car_detail", "--vector object "
                                              "--method mapping --watertight off")),
    # Farm shards (docs/FARM.md): merged, each equals the one extraction beside it.
    case("shards_single", extract(SPOT, "spot_jittered", SHARD_OPTIONS), rays=True),
    case("shards_whole_3", [
        f"extract {SPOT} {{s}}/spot_jittered.obj -o part{i}.ptx {SHARD_OPTIONS} --shard {i}/3"
        for i in (1, 2, 3)] + ["merge part3.ptx part1.ptx part2.ptx -o map.ptx"],
        equal="shards_single", rays=True),
    case("shards_part_2", [
        f"extract {SPOT} {{s}}/spot_jittered.obj -o part{i}.ptx {SHARD_OPTIONS} --shard {i}/2 "
        "--shard-sculpt part" for i in (1, 2)] + ["merge part1.ptx part2.ptx -o map.ptx"],
        equal="shards_single", rays=True),
    case("shards_interpolate_2", [
        f"extract {SPOT} {{s}}/spot_detail.obj -o part{i}.ptx --shard {i}/2" for i in (1, 2)]
        + ["merge part2.ptx part1.ptx -o map.ptx"], equal="scalar_auto"),
    # Incremental (docs/INCREMENTAL.md): a re-run after a local edit of the sculpt, or a changed
    # option, equals the full extraction; an unchanged re-run leaves the map as it is.
    case("edited_full", "extract " + SPOT + " {s}/spot_detail_edited.obj -o map.ptx --method rays "
         "--search-distance 1%", rays=True),
    case("incremental_sculpt", [
        "@copy {s}/spot_detail.obj in/sculpt.obj",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --method rays --search-distance 1%",
        "@copy {s}/spot_detail_edited.obj in/sculpt.obj",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --method rays --search-distance 1% "
        "--incremental",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --method rays --search-distance 1% "
        "--incremental"], rays=True),
    case("incremental_sculpt_full", [
        "@copy {s}/spot_detail_edited.obj in/sculpt.obj",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --method rays --search-distance 1%"],
        equal="incremental_sculpt", rays=True),
    case("incremental_option", [
        extract(SPOT, "spot_jittered"),
        extract(SPOT, "spot_jittered", "--watertight all --incremental")],
        equal="jittered_all", rays=True),
    case("incremental_vector", [
        "@copy {s}/spot_overhang.obj in/sculpt.obj",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --vector tangent",
        "@copy {s}/spot_overhang_edited.obj in/sculpt.obj",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --vector tangent --incremental"]),
    case("incremental_vector_full", [
        "@copy {s}/spot_overhang_edited.obj in/sculpt.obj",
        f"extract {SPOT} in/sculpt.obj -o map.ptx --vector tangent"],
        equal="incremental_vector"),
    # UV-space maps (docs/UV_MAPS.md): the Ptex map and every UDIM tile.
    case("uv_box", extract(BOX, "box_detail", "--uv-maps uv --uv-resolution 64"),
         files=("map.ptx", "uv/*.exr"), rays=True),
    case("uv_box_vector_object", extract(BOX, "box_detail", "--vector object --uv-maps uv "
                                         "--uv-resolution 64"), files=("map.ptx", "uv/*.exr")),
    case("uv_spot_half", extract(SPOT, "spot_jittered", "--data-type half --uv-maps uv "
                                 "--uv-resolution 128 --uv-padding 4"),
         files=("map.ptx", "uv/*.exr"), rays=True),
    # Assets of several shapes (docs/SHAPES.md): OBJ groups, a manifest, a batch.
    case("shapes_groups", "extract {s}/asset_base.obj {s}/asset_sculpt.obj --out-dir maps",
         files=("maps/*.ptx",), rays=True),
    case("shapes_manifest", ["@manifest shapes", "extract --manifest shapes.json --out-dir maps"],
         files=("maps/*.ptx",), rays=True),
    case("batch", ["@manifest batch", "batch batch.json"], files=("maps/*.ptx",), rays=True),
    # The thread count changes nothing.
    case("threads_1_rays", extract(SPOT, "spot_detail", "--method rays --threads 1"),
         equal="scalar_rays", rays=True),
    case("threads_1_jittered_all", extract(SPOT, "spot_jittered", "--watertight all --threads 1"),
         equal="jittered_all", rays=True),
    case("threads_1_vector", extract(SPOT, "spot_overhang", "--vector object --threads 1"),
         equal="vector_object"),
]

MANIFESTS = {
    "shapes": {"options": {"max_oversample": 64}, "shapes": [
        {"name": "spot", "base": SPOT, "sculpt": "{s}/spot_jittered.obj",
         "options": {"tolerance": 0.002, "watertight": "off"}},
        {"name": "wavy", "base": WAVY, "sculpt": "{s}/wavy_image.obj",
         "options": {"search_distance": "2%", "data_type": "half"}}]},
    "batch": {"options": {"search_distance": "1%"}, "assets": [
        {"name": "spot", "base": SPOT, "sculpt": "{s}/spot_detail.obj", "output_dir": "maps"},
        {"name": "spot_half", "base": SPOT, "sculpt": "{s}/spot_jittered.obj",
         "output_dir": "maps", "options": {"data_type": "half", "method": "rays"}}]},
}


class Failure(Exception):
    pass


class Skip(Exception):
    pass


def expand(text, paths):
    return text.replace("{data}", paths["data"]).replace("{s}", paths["s"])


def run_dispex(args, cwd, options):
    if options.threads is not None and "--threads" not in args:
        args = args + ["--threads", str(options.threads)]
    cmd = shlex.split(options.wrapper) + [options.dispex] + args + ["-q"]
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0 and options.embree_isa and "this CPU lacks" in r.stderr:
        raise Skip(f"this CPU lacks the Embree ISA {options.embree_isa}: {r.stderr.strip()}")
    if r.returncode != 0:
        raise Failure(f"`{' '.join(args)}` exited {r.returncode}: {(r.stderr or r.stdout).strip()}")


def edit_sculpt(src, dst):
    """A local edit: the vertices within a ball around vertex n/3, holding 2% of them, moved
    along +z by a polynomial bump (+, -, *, / only, no libm: the same bits on every CPU)."""
    with open(src) as f:
        lines = f.readlines()
    points = [tuple(float(x) for x in line.split()[1:4]) for line in lines if line.startswith("v ")]
    c = points[len(points) // 3]
    d2 = [sum((a - b) * (a - b) for a, b in zip(p, c)) for p in points]
    r2 = sorted(d2)[len(d2) // 50]
    amplitude = 0.002
    out, index = [], 0
    for line in lines:
        if line.startswith("v "):
            x, y, z = points[index]
            if d2[index] < r2:
                w = 1 - d2[index] / r2
                z += amplitude * w * w
                line = "v %.9g %.9g %.9g\n" % (x, y, z)
            index += 1
        out.append(line)
    with open(dst, "w") as f:
        f.writelines(out)


def group_meshes(parts, dst):
    """One OBJ of several shapes (`o NAME`), from (name, file) pairs: positions and faces only."""
    out, offset = [], 0
    for name, path in parts:
        out.append(f"o {name}\n")
        count = 0
        with open(path) as f:
            for line in f:
                fields = line.split()
                if not fields:
                    continue
                if fields[0] == "v":
                    out.append(line if line.endswith("\n") else line + "\n")
                    count += 1
                elif fields[0] == "f":
                    ids = [int(x.split("/")[0]) for x in fields[1:]]
                    out.append("f " + " ".join(str(i + offset if i > 0 else i) for i in ids) + "\n")
        offset += count
    with open(dst, "w") as f:
        f.writelines(out)


def make_sculpts(paths, options):
    for name, spec in SCULPTS.items():
        folder = os.path.join(paths["work"], "sculpts")
        dst = name + ".obj"
        if spec.startswith("@edit "):
            edit_sculpt(os.path.join(folder, spec.split()[1] + ".obj"), os.path.join(folder, dst))
        elif spec.startswith("@group "):
            group_meshes([(p.split("=")[0], os.path.join(folder, expand(p.split("=", 1)[1], paths)))
                          for p in spec.split()[1:]], os.path.join(folder, dst))
        else:
            run_dispex(shlex.split(expand(spec, paths)) + ["-o", dst], folder, options)


def sculpt_hash(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for line in f:
            if not line.startswith(b"#"):
                h.update(line)
    return h.hexdigest()


def file_hash(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def run_case(c, paths, options):
    folder = os.path.join(paths["work"], c["name"])
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(os.path.join(folder, "in"))
    for step in c["run"]:
        step = expand(step, paths)
        words = shlex.split(step)
        if words[0] == "@copy":
            shutil.copyfile(os.path.join(folder, words[1]), os.path.join(folder, words[2]))
        elif words[0] == "@manifest":
            text = expand(json.dumps(MANIFESTS[words[1]], indent=1), paths)
            with open(os.path.join(folder, words[1] + ".json"), "w") as f:
                f.write(text)
        else:
            run_dispex(words, folder, options)
    files = {}
    for pattern in c["files"]:
        found = sorted(glob.glob(os.path.join(folder, pattern)))
        if not found:
            raise Failure(f"wrote no file {pattern}")
        for path in found:
            files[os.path.relpath(path, folder)] = file_hash(path)
    return files


def dispex_version(options):
    r = subprocess.run(shlex.split(options.wrapper) + [options.dispex, "--version"],
                       capture_output=True, text=True)
    return r.stdout.strip().split()[-1] if r.returncode == 0 and r.stdout.strip() else "?"


def package_versions():
    """The Debian packages whose code decides the bytes (compression, rays, FFTs, libm)."""
    packages = ["libdeflate0", "zlib1g", "libopenexr-3-1-30", "libembree3-3", "libfftw3-single3",
                "libosdcpu3.5.0", "libc6"]
    try:
        r = subprocess.run(["dpkg-query", "-W", "-f", "${Package} ${Version}\n"] + packages,
                           capture_output=True, text=True)
    except OSError:
        return {}
    return dict(line.split(" ", 1) for line in r.stdout.splitlines() if " " in line)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dispex", default=os.path.join(ROOT, "build", "tools", "dispex"))
    parser.add_argument("--work", help="folder for the outputs (emptied first; default: a "
                        "temporary folder), removed unless a case fails or --keep")
    parser.add_argument("--keep", action="store_true", help="keep the outputs")
    parser.add_argument("--only", help="only the cases whose name matches this regex")
    parser.add_argument("--update", action="store_true", help="rewrite the stored hashes")
    parser.add_argument("--embree-isa", choices=EMBREE_ISAS,
                        help="run under DISPEX_EMBREE_ISA=ISA (only the cases that cast rays)")
    parser.add_argument("--threads", type=int, help="every command at this many threads "
                        "(the hashes must not change)")
    parser.add_argument("--wrapper", default="", help="a command each dispex run goes through "
                        "(e.g. 'qemu-x86_64 -cpu Nehalem' to run as on another CPU)")
    parser.add_argument("--list", action="store_true", help="list the cases and exit")
    options = parser.parse_args()
    if options.list:
        for c in CASES:
            print(f"{c['name']:28} " + " ; ".join(c["run"]))
        return 0
    if not os.access(options.dispex, os.X_OK):
        print(f"golden: no dispex at {options.dispex} (build it, or give --dispex)",
              file=sys.stderr)
        return 2
    if options.update and (options.only or options.embree_isa or options.wrapper or
                           options.threads is not None):
        print("golden: --update rewrites every case: no --only, --embree-isa, --threads or "
              "--wrapper", file=sys.stderr)
        return 2
    os.environ.pop("DISPEX_MAPPING_KERNEL", None)
    os.environ.pop("DISPEX_EMBREE_ISA", None)
    selected = [c for c in CASES if not options.only or re.search(options.only, c["name"])]
    if options.embree_isa:
        os.environ["DISPEX_EMBREE_ISA"] = options.embree_isa
        selected = [c for c in selected if c["rays"]]
    # A case compared with another needs that one too.
    names = {c["name"] for c in selected}
    for c in list(selected):
        if c["equal"] and c["equal"] not in names:
            selected.append(next(x for x in CASES if x["name"] == c["equal"]))
            names.add(c["equal"])
    selected.sort(key=lambda c: [x["name"] for x in CASES].index(c["name"]))

    if options.work:
        work = os.path.abspath(options.work)
        if os.path.isdir(work) and os.listdir(work) and \
                not os.path.exists(os.path.join(work, WORK_MARK)):
            print(f"golden: {work} holds other files: --work takes a new folder or one of an "
                  "earlier run (it is emptied)", file=sys.stderr)
            return 2
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
    else:
        work = tempfile.mkdtemp(prefix="golden_")
    open(os.path.join(work, WORK_MARK), "w").close()
    # Inputs are named by relative paths, the same in every work folder: UV-space tiles record
    # the base and sculpt as the command line names them (a Ptex map, their file names only).
    paths = {"data": "../data", "work": work, "s": "../sculpts"}
    sculpts_dir = os.path.join(work, "sculpts")
    shutil.rmtree(sculpts_dir, ignore_errors=True)
    os.makedirs(sculpts_dir)
    if os.path.lexists(os.path.join(work, "data")):
        os.unlink(os.path.join(work, "data"))
    os.symlink(DATA, os.path.join(work, "data"))
    stored = {}
    if os.path.exists(HASHES):
        with open(HASHES) as f:
            stored = json.load(f)
    version = dispex_version(options)
    start = time.monotonic()
    problems = []

    try:
        make_sculpts(paths, options)
    except Failure as e:
        print(f"golden: making the sculpts: {e}", file=sys.stderr)
        return 1
    sculpts = {name: sculpt_hash(os.path.join(sculpts_dir, name + ".obj")) for name in SCULPTS}
    if not options.update:
        for name, h in sculpts.items():
            want = stored.get("sculpts", {}).get(name)
            if want != h:
                problems.append(f"sculpt {name}: sha256 {h}, stored {want}: the test's input "
                                "changed (make-sculpt or this script), so the maps made from it "
                                "differ too")

    results, times = {}, {}
    isa_note = "".join([f" under DISPEX_EMBREE_ISA={options.embree_isa}" if options.embree_isa
                        else "", f" at --threads {options.threads}" if options.threads else "",
                        f" through `{options.wrapper}`" if options.wrapper else ""])
    for c in selected:
        t0 = time.monotonic()
        try:
            results[c["name"]] = run_case(c, paths, options)
        except Skip as e:
            print(f"golden: skipped: {e}")
            shutil.rmtree(work, ignore_errors=True)
            return 77
        except Failure as e:
            problems.append(f"case {c['name']}{isa_note}: {e}")
            continue
        finally:
            times[c["name"]] = time.monotonic() - t0
    for c in selected:
        other = c["equal"]
        if other and c["name"] in results and other in results and \
                results[c["name"]] != results[other]:
            problems.append(f"case {c['name']}{isa_note}: its files must equal case {other}'s "
                            f"byte for byte (a property of dispex, whatever is stored): "
                            f"{results[c['name']]} against {results[other]}")

    stored_cases = stored.get("cases", {})
    if not options.update:
        for c in selected:
            name = c["name"]
            if name not in results:
                continue
            want = stored_cases.get(name)
            if want is None:
                problems.append(f"case {name}: no stored hashes (a new case? run "
                                "tests/golden/golden_maps.py --update)")
                continue
            for file in sorted(set(want["files"]) | set(results[name])):
                got, expected = results[name].get(file), want["files"].get(file)
                if got != expected:
                    problems.append(f"case {name}{isa_note}, file {file}: sha256 "
                                    f"{got or '(not written)'}, stored {expected or '(none)'}"
                                    "\n    made by: " + " ; ".join(c["run"]))
        if not options.only and not options.embree_isa:
            for name in sorted(set(stored_cases) - {c["name"] for c in CASES}):
                problems.append(f"case {name}: stored but no longer in the list (run --update)")

    elapsed = time.monotonic() - start
    slowest = sorted(times.items(), key=lambda kv: -kv[1])[:5]
    print(f"golden: {len(results)} of {len(selected)} cases ran{isa_note} in {elapsed:.1f} s "
          f"(slowest: " + ", ".join(f"{n} {t:.2f} s" for n, t in slowest) + ")")
    if problems:
        made = stored.get("made_with", {})
        print(f"golden: {len(problems)} problem(s):", file=sys.stderr)
        for p in problems:
            print("  " + p, file=sys.stderr)
        if made.get("dispex_version") and made["dispex_version"] != version:
            print(f"golden: the stored hashes were made by dispex {made['dispex_version']}, this "
                  f"is {version}: every map records the version, so every hash changes with it",
                  file=sys.stderr)
        if not options.update:
            print("golden: the maps are no longer byte-identical to the stored ones. If the change "
                  "of the maps is intended, regenerate with `tests/golden/golden_maps.py --update` "
                  "and say why in the commit; if it is not, the change broke them. The outputs "
                  f"are kept in {work} (compare them with `dispex info`, or bench/extract's "
                  "compare_maps against a build of the previous commit).", file=sys.stderr)
        return 1
    if options.update:
        document = {
            "about": "sha256 of every file each case of tests/golden/golden_maps.py writes "
                     "(`sculpts`: the make-sculpt inputs, comment lines left out); {data} is "
                     "tests/data, {s} the sculpts. Made by `golden_maps.py --update`: regenerate "
                     "only for an intended change of the maps, and say why in the commit.",
            "made_with": {
                "dispex_version": version,
                "machine": platform.machine(),
                "embree_isa": "the CPU's own (DISPEX_EMBREE_ISA unset): maps are the same "
                              "under every ISA (docs/DEVELOPING.md, \"Golden map hashes\")",
                "threads": "all cores (the threads_1 cases: one)",
                "packages": package_versions(),
            },
            "sculpts": sculpts,
            "cases": {c["name"]: {"run": c["run"], "files": results[c["name"]]} for c in CASES},
        }
        with open(HASHES, "w") as f:
            json.dump(document, f, indent=1, sort_keys=False)
            f.write("\n")
        print(f"golden: wrote {os.path.relpath(HASHES, ROOT)} ({len(CASES)} cases)")
    if not options.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
