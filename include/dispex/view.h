// Review pages: one self-contained HTML file that shows a displacement map on the surface it
// displaces, for people who review maps by looking (`dispex view`, docs/COMMANDS.md).
//
// The page holds everything it shows -- three.js (r111, Debian's libjs-three, embedded into the
// library when it is built), the geometry, the map's report and atlas -- and fetches nothing
// when it is opened: it opens from disk or from any web share, with no server and nothing
// installed. Its content security policy forbids every request besides inline scripts, styles
// and data: images.
//
// What it shows, in WebGL: the base's Catmull-Clark limit surface, evaluated on a grid per Ptex
// face, displaced by the map as a renderer reads it (a scalar Ptex map through the reference
// Ptex filter across face edges, P + h N; a vector map per face in its own frame, P + D; a
// UV-space map through the cage's UVs); the limit surface itself; the sculpt, decimated for the
// page. Colours: the displacement (green +, red -, as `dispex preview` draws it; a vector map's
// normal part D.N), each face's stored resolution, the error `dispex verify --report` measured
// per face (in tolerances), the samples each face's extraction missed and filled; a click on a
// face shows its id, resolution, values, error and holes. A panel shows the map's settings and
// statistics (its dispex:* meta data), the extraction's times (with its --report) and the
// verify report, and the atlas (`dispex preview`) as an image.
//
// Level of detail: every quad Ptex face gets the same grid of `grid` x `grid` quads (the
// sub-faces of n-gons, half as many per side, so that points along the base's edges are
// spaced alike and shared by the faces on both sides: the surface is one mesh without cracks,
// its displaced points averaged where faces meet), the finest that keeps within max_vertices
// (even on a base with n-gons);
// the sculpt is decimated by vertex clustering to at most max_sculpt_vertices. The page states
// both. Geometry is stored compactly: limit points as 21-bit fixed point, displacements and
// values as 16-bit, base64 in the page's JSON.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dispex/status.h"

namespace dispex {

struct ViewPageOptions {
  std::string base_path;  // the base cage (OBJ, PLY)
  // The map: a Ptex file (scalar or vector), or a UV-space map -- DIR/<shape>.<UDIM>.exr with the
  // literal <UDIM>, or one of its tiles (include/dispex/uv_map.h).
  std::string map_path;
  std::string sculpt_path;          // optional: shown decimated
  std::string verify_report_path;   // optional: what `dispex verify --report` wrote for the map
  std::string extract_report_path;  // optional: what `dispex extract --report` wrote (times)
  std::string extract_report_json;  // or that report itself, as JSON text (`dispex batch --view`)
  std::string title;                // empty: the map's file name
  // Vertices of the surface on the page (points shared by faces count once): the grid is the
  // finest within it. 1000..50,000,000.
  std::int64_t max_vertices = 500'000;
  // Vertices of the decimated sculpt (0: no sculpt even when given). 0..10,000,000.
  std::int64_t max_sculpt_vertices = 150'000;
  // Quads per side of every quad Ptex face: 0 for the finest within max_vertices and max_grid,
  // else this (1..256; even on a base with n-gons, whose sub-faces take half).
  int grid = 0;
  int max_grid = 64;  // 1..256
  // The atlas `dispex preview` draws (a Ptex map), as a PNG in the page, when its PNG takes
  // at most max_atlas_bytes (0: no atlas).
  std::int64_t max_atlas_bytes = 2 << 20;
  int threads = 0;  // 0: all cores
};

// Checks every option's range; the message names the field and its value.
Status ValidateViewPageOptions(const ViewPageOptions& options);

// What was put on a page.
struct ViewPageReport {
  std::string map_kind;      // "scalar", "vector" or "uv" + " scalar" / " vector"
  std::string vector_space;  // of a vector map
  int ptex_faces = 0;
  int grid = 0;  // quads per side of a quad face (sub-faces: grid / 2)
  std::int64_t surface_vertices = 0, surface_triangles = 0;
  // The sculpt: as read, and on the page (0 when none); the clustering's cell size (0 when
  // the sculpt fitted whole).
  std::int64_t sculpt_vertices_read = 0, sculpt_faces_read = 0;
  std::int64_t sculpt_vertices = 0, sculpt_triangles = 0;
  double sculpt_cell = 0;
  bool atlas = false;
  // Why a part is left out or partial: one line each ("atlas: 5.2 MB PNG, over ...",
  // "verify: per-face errors not in the report: the 10 worst faces only").
  std::vector<std::string> notes;
  bool verify_per_face = false;  // per-face errors from the verify report, every face
  bool holes_per_face = false;   // per-face misses from the map's records
  // Bytes of the page and of its parts.
  std::int64_t page_bytes = 0, three_js_bytes = 0, surface_bytes = 0, sculpt_bytes = 0,
               atlas_bytes = 0;
  double seconds = 0;
  // Wall seconds by phase: "base" (read, limit surface), "map" (read), "surface" (evaluated,
  // displaced, joined), "sculpt" (read, decimated), "atlas", "page" (encoded, assembled).
  std::vector<std::pair<std::string, double>> phase_seconds;
  std::vector<std::string> warnings;  // one line each (tags of the base that were ignored)
};

// The page as a string. Fails, naming the file, for inputs that cannot be read, a map of
// another base (face counts differ), a map that is neither scalar nor vector, a verify report
// of another map, and options out of range.
StatusOr<std::string> MakeViewPage(const ViewPageOptions& options,
                                   ViewPageReport* report = nullptr);

// MakeViewPage written to `output_path` atomically (include/dispex/files.h).
StatusOr<ViewPageReport> WriteViewPage(const ViewPageOptions& options,
                                       const std::string& output_path);

// The report as JSON (`dispex view --report`).
std::string ViewPageReportJson(const ViewPageReport& report);

// ---- An index of pages (a batch) ----------------------------------------------------------

struct ViewIndexEntry {
  std::string name;    // the asset
  std::string page;    // the page's path relative to the index (empty: none)
  std::string status;  // "ok", "failed", ...
  std::string note;    // one line: the error, or what the map holds
};

// One HTML page listing `entries` with links to their pages; self-contained as the pages are.
std::string MakeViewIndex(const std::string& title, const std::vector<ViewIndexEntry>& entries);

}  // namespace dispex
