// Shapes: the subdivision surfaces of one asset, as the OBJ `o`/`g` groups of its files name
// them. Each shape is extracted with its own map; a base shape and a sculpt shape pair by name.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

// One subdivision surface of an asset, with its own map.
struct MeshShape {
  // The group's name (Mesh::group_names; "default" for the faces before the first o/g line).
  // For a mesh without groups, the stem of Mesh::source's file name ("bunny" for
  // /a/b/bunny.obj), or "mesh" when that is empty.
  std::string name;
  std::string file_name;  // ShapeFileNames' name for `name`, without extension
  Mesh mesh;              // the shape's faces alone
};

// The shapes of `mesh`, one per group in group order (Mesh::group_names). A mesh without
// groups, or with a single group, is one shape holding the whole mesh (a copy: `source`,
// vertices, unreferenced ones included, and tags unchanged).
//
// With several groups, each shape's mesh is what a file holding only that shape's faces and the
// vertices they use would give: faces in file order; vertices (and UVs) those the shape's faces
// use, in ascending order of their ids in `mesh`; creases whose two vertices are both in the
// shape, corners and holes of the shape, renumbered; the tag settings (boundary, crease method,
// triangles, their *_from_file flags, ignored tag names) and faces_without_uvs copied; no
// groups; positions.capacity() > positions.size() (Embree). Its `source` is the parent's followed
// by " shape 'NAME'", so that its messages read "base.obj shape 'head': ...".
//
// `require_disjoint` (base cages): two shapes that share a vertex are one surface, an error
// naming both and the vertex, 1-based as in the OBJ's f lines ("base.obj: shapes 'a' and 'b'
// share vertex 17; ..."); so is a crease from one shape's vertex to another's. Sculpts pass
// false: a vertex used by several shapes is copied into each, and a crease between two shapes is
// dropped. Texture coordinates used by several shapes are copied into each in both modes.
//
// Errors (one line, starting with Mesh::source): face_groups without one in-range group id per
// face, two groups of the same name, a group without faces, a face index, texture index or tag
// id out of range, the disjointness above. Otherwise `mesh` must be well formed as the readers
// return it (face_offsets from 0 to face_indices.size()). Linear time; parallel over faces and
// shapes; the result does not depend on the thread count.
StatusOr<std::vector<MeshShape>> SplitShapes(const Mesh& mesh, bool require_disjoint);
// The same, moving a single-shape mesh into its shape instead of copying it (`mesh` is then
// left empty; with several shapes it is left as it was).
StatusOr<std::vector<MeshShape>> SplitShapes(Mesh&& mesh, bool require_disjoint);

// Safe, distinct file names (without extension) for shape names, in the same order:
//  1. Every byte outside [A-Za-z0-9._-] becomes '_', a leading '.' becomes '_', a name longer
//     than 100 bytes is cut to its first 100; an empty name becomes "shape".
//  2. When that changed the name, "-" and the 8 lowercase hex digits of the CRC-32 of the
//     original name are appended ("a/b" -> "a_b-07f4401c", "" -> "shape-00000000").
//  3. Names whose results so far are equal ignoring ASCII letter case (case-insensitive file
//     systems) get that suffix too, where they do not have it yet ("Head" and "head" ->
//     "Head-07c159a2" and "head-a7f3f69c"; "a/b" and "a_b" -> "a_b-07f4401c" and "a_b").
//  4. A result still equal to an earlier one ignoring case (the same CRC, or a name that reads
//     like another's suffixed one) gets "-2", "-3", ...: the lowest number that no result has.
// A name that is already safe and unlike every other keeps exactly its name.
std::vector<std::string> ShapeFileNames(std::span<const std::string> names);

// The pairs of base and sculpt shapes to extract, in the base's shape order: pair i is
// base[base_index[i]] with sculpt[sculpt_index[i]].
struct ShapeMatch {
  std::vector<std::size_t> base_index;
  std::vector<std::size_t> sculpt_index;
  std::vector<std::string> warnings;  // one line each
};

// Pairs the base's shapes with the sculpt's by name: the base shapes named in `selected`
// (empty: all of them), each with the sculpt shape of exactly the same name. When both have a
// single shape, those two pair whatever their names (one mesh, one sculpt). The order of the
// result is the base's, never that of `selected`.
//
// Errors, one line each, listing the shapes found (the first 10): a name selected twice; a
// selected name that is no base shape ("selected shape 'x' is not in base.obj (its shapes:
// 'head', 'body')"); a selected base shape without a sculpt shape of its name ("sculpt.obj has
// no shape 'belt' (its shapes: 'Belt ', 'head')"), with a hint when a name differs from it only in
// letter case or blanks ("; shape names must match exactly: 'Belt ' differs from 'belt' only in
// letter case or blanks"); two shapes of the same name in base or sculpt; no shapes.
// Warnings: a sculpt shape whose name is no base shape's is not used ("sculpt.obj: shape 'x' has
// no base shape of that name; not used").
StatusOr<ShapeMatch> MatchShapes(std::span<const MeshShape> base, std::span<const MeshShape> sculpt,
                                 std::span<const std::string> selected,
                                 const std::string& base_source, const std::string& sculpt_source);

}  // namespace dispex
