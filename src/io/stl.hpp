#pragma once
// STL triangle meshes (the stereolithography format): reading ASCII and binary files, and placing a mesh in the
// scene by scale, rotation and translation. No physics: the walls made from a mesh live above this layer.
//
// Format (the de-facto standard of 3D Systems' StereoLithography Interface Specification, 1989):
//  * binary: an 80-byte header, a little-endian uint32 triangle count n, then n records of 50 bytes (normal and
//    three vertices as 12 little-endian float32, a uint16 attribute); the file has exactly 84 + 50 n bytes.
//  * ASCII: `solid NAME`, then per triangle `facet normal nx ny nz` / `outer loop` / three `vertex x y z` /
//    `endloop` / `endfacet`, then `endsolid [NAME]` (several solids in one file are read one after the other).
// The stored normals are not used: a triangle's orientation is its vertex order (counter-clockwise seen from the
// side its normal points to), which the readers keep.
//
// Which format: a file whose size is 84 + 50 n for the count n at byte 80 is binary, even if it starts with
// "solid" (many exporters write that into the binary header; an ASCII file cannot match by chance below 7 GB, as its
// bytes 80-83 are text, a count of at least 0x09090909). Otherwise a file that starts with "solid" and has no
// control byte (NUL and the like; ASCII STL is text) in its first 84 bytes is ASCII; anything else is binary, and
// then its size is wrong: truncated or with trailing bytes.
#include <array>
#include <cstddef>
#include <filesystem>
#include <istream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace haet {

/// A triangle as its three vertices, in the order of the file (file units, or metres once placed).
using StlTriangle = std::array<Vec<3>, 3>;

/// Bad STL input. The message is "FILE[:LINE]: [triangle K: ]what", K 1-based in file order; line() is the
/// 1-based line of an ASCII file, 0 for a binary file or when no line applies, triangle() 0 when none applies.
class StlError : public std::runtime_error {
public:
    StlError(const std::filesystem::path& path, const std::string& what, std::size_t triangle = 0, int line = 0);
    const std::filesystem::path& path() const { return path_; }
    std::size_t triangle() const { return triangle_; }
    int line() const { return line_; }

private:
    std::filesystem::path path_;
    std::size_t triangle_;
    int line_;
};

/// A triangle is degenerate (zero area) when its height over its longest edge is at most this fraction of that
/// edge: |(p1 - p0) x (p2 - p0)| <= kStlDegenerateRatio * L_max^2 (twice the area over L_max^2 is that ratio).
/// Far above double round-off of the cross product for a triangle within 10^5 of its own size from the origin
/// (relative error ~ 1e-16 |p| / L), far below any triangle a contact could use. A float32 binary file resolves
/// only ~1e-7 of its coordinates, so a triangle meant to be collinear there passes as a sliver of that ratio:
/// harmless to a contact (its edges and vertices are exact), so not rejected.
inline constexpr double kStlDegenerateRatio = 1e-10;

struct StlMesh {
    std::filesystem::path path;          ///< the file it was read from (errors name it)
    std::string name;                    ///< ASCII: the text after `solid` (first solid); binary: the header text
    bool binary = false;                 ///< which format the file was
    std::vector<StlTriangle> triangles;  ///< in file order, vertices as written (file units)
};

/// Reads an ASCII or binary STL file (format above). Throws StlError for: a missing or unreadable file; an empty
/// file or one with no triangles; a binary file shorter than its count says (naming the first incomplete
/// triangle) or longer; malformed ASCII (unknown or misplaced keyword, a bad number, a facet with other than
/// three vertices, binary bytes in text, end of file inside a solid: with the line); a non-finite coordinate;
/// a degenerate triangle (kStlDegenerateRatio). Memory is bounded by the file: a binary count is checked
/// against the file's size before anything is allocated, and ASCII is read line by line.
StlMesh readStl(const std::filesystem::path& path);
/// The same from a seekable stream (what the file's overload reads; the fuzz target's entry), `path` naming it.
StlMesh readStl(std::istream& in, const std::filesystem::path& path);

/// Placement of a mesh: p' = R (S p) + T, in this order: scale about the origin of the file's coordinates, then
/// rotate about that origin, then translate. A negative scale factor mirrors; with an odd number of them the
/// vertex order of every triangle is reversed (vertices 1 and 2 swapped) so that orientations stay outward.
struct StlTransform {
    Vec<3> scale{{1, 1, 1}};      ///< per axis factor (dimensionless; file units to metres); a scalar s is {s, s, s}
    Vec<3> axis{{0, 0, 1}};       ///< rotation axis (any length > 0 when angle_deg != 0)
    double angle_deg = 0;         ///< rotation angle about `axis`, right-handed (degrees)
    Vec<3> translate{{0, 0, 0}};  ///< translation applied last (m)
};

/// R of an axis-angle rotation (Rodrigues' formula), rows of the matrix: p' = (r[0].p, r[1].p, r[2].p).
std::array<Vec<3>, 3> stlRotation(const Vec<3>& axis, double angleDeg);

/// Applies `t` to every triangle of `mesh` (StlTransform). Throws std::invalid_argument for a non-finite or zero
/// scale factor, a zero or non-finite axis with a non-zero angle, a non-finite angle or translation; StlError
/// (naming mesh.path and the triangle) when a triangle becomes degenerate (a very anisotropic scale).
void transformStl(StlMesh& mesh, const StlTransform& t);

/// Writes triangles as an ASCII STL text (the normals from the vertex order; "%.17g", so reading gives the same
/// doubles back). For tests and tools; the program reads meshes, it does not write them.
std::string stlAscii(const std::vector<StlTriangle>& triangles, const std::string& name);
/// Writes triangles as a binary STL (coordinates rounded to float32), header text `header` (cut to 80 bytes).
std::string stlBinary(const std::vector<StlTriangle>& triangles, const std::string& header);

}  // namespace haet
