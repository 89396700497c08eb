"""Prints the benchmark table from the extraction reports and writes it all as JSON."""
import json
import os
import platform
import sys

PUBLISHED = {  # Embree backend, their workstation, 64x64 oversampling
    "cape": {"base": "4K", "sculpt": "4.2M", "seconds": 7.5, "texels": "17M -> 7M"},
    "head": {"base": "8K", "sculpt": "8M", "seconds": 15.8, "texels": "32M -> 11M"},
    "body": {"base": "17K", "sculpt": "16M", "seconds": 26.7, "texels": "69M -> 30M"},
}


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def main():
    out, json_path, component_path, names = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    rows = []
    for name in names:
        r = json.load(open(os.path.join(out, name + "-report.json")))
        v = json.load(open(os.path.join(out, name + "-verify.json")))
        s, p = r["statistics"], r["phases_seconds"]
        rows.append({
            "asset": name,
            "base_faces": s["base"]["faces"],
            "sculpt_polygons": s["sculpt"]["faces"],
            "read_base": p["read_base"], "read_sculpt": p["read_sculpt"], "bvh": p["bvh"],
            "sample_trace": p["sample_trace"], "write": p["write"],
            "auto_settings": p["auto_settings"], "total": p["total"],
            "cpu_limit": r["cpu_seconds"]["limit"], "cpu_trace": r["cpu_seconds"]["trace"],
            "cpu_spectral": r["cpu_seconds"]["spectral"],
            "mrays_per_second": r["mrays_per_second"],
            "oversampled_texels": s["texels"]["oversampled"],
            "written_texels": s["texels"]["written"],
            "written_fraction": s["texels"]["written_fraction"],
            "file_bytes": r["output"]["bytes"],
            "peak_rss_bytes": r["peak_rss_bytes"],
            "tolerance": s["tolerance"],
            "truth_max": v["truth"]["max"], "truth_rms": v["truth"]["rms"],
            "misses": s["misses"],
            "published": PUBLISHED.get(name),
        })
    head = ("| asset | base faces | sculpt polys | read base | read sculpt | BVH | sample+trace "
            "| write | total | Mrays/s | texels oversampled → written | file | peak RSS "
            "| error max / tolerance | published |")
    print(head)
    print("|" + "|".join(["---"] * (head.count("|") - 1)) + "|")
    for x in rows:
        pub = x["published"]
        pub_text = f'{pub["seconds"]} s, {pub["texels"]}' if pub else ""
        print(f'| {x["asset"]} | {x["base_faces"]:,} | {x["sculpt_polygons"]:,} '
              f'| {x["read_base"]:.2f} s | {x["read_sculpt"]:.2f} s | {x["bvh"]:.2f} s '
              f'| {x["sample_trace"]:.2f} s | {x["write"]:.2f} s | **{x["total"]:.2f} s** '
              f'| {x["mrays_per_second"]:.1f} '
              f'| {x["oversampled_texels"]/1e6:.1f}M → {x["written_texels"]/1e6:.1f}M '
              f'({100*x["written_fraction"]:.0f}%) | {x["file_bytes"]/1e6:.1f} MB '
              f'| {x["peak_rss_bytes"]/2**30:.2f} GiB '
              f'| {x["truth_max"]:.3g} / {x["tolerance"]:.3g} | {pub_text} |')
    components = json.load(open(component_path)) if component_path else None
    if components:
        print()
        print("| component (body asset, 2 threads) | figure |")
        print("|---|---|")
        for k, val in components.items():
            print(f"| {k} | {val} |")
    result = {"machine": {"cpu": cpu_model(), "cores": os.cpu_count()}, "assets": rows,
              "components": components}
    with open(json_path, "w") as f:
        json.dump(result, f, indent=2)
    print(f"\nmachine: {cpu_model()}, {os.cpu_count()} cores; JSON: {json_path}")


if __name__ == "__main__":
    main()
