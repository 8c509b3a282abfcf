#pragma once
// VTK XML output for ParaView: particles as an UnstructuredGrid (.vtu), walls as PolyData (.vtp), and a
// .pvd collection that maps files to simulation times.
//
// Arrays use the binary "appended raw" encoding (header_type UInt64, LittleEndian): the XML head gives each
// array's byte offset, and the raw blocks follow one `_` marker, each prefixed by its byte count as UInt64.
// Chosen over inline base64 because it is the fastest to write and to read and needs no encoding step;
// the blocks are streamed straight from the caller's arrays. Every file is written atomically.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace haet {

/// One named array attached to points or cells. Not owning: `data` must stay valid during the write call.
struct VtkField {
    enum Type { Float64, Int32, Int64, UInt8 };
    std::string name;
    int components = 1;  ///< values per point or cell (3 for a vector)
    Type type = Float64;
    const void* data = nullptr;  ///< count*components values of `type`, interleaved (x0 y0 z0 x1 ...)
};

/// Writes n points as VTK_VERTEX cells. xyz holds 3*n coordinates [m] (2D callers pass z = 0).
/// `time` [s] is stored as the FieldData array TimeValue. Throws IoError, or std::invalid_argument for a
/// malformed field.
void writeVtuPoints(const std::filesystem::path& path, std::size_t n, const double* xyz,
                    const std::vector<VtkField>& pointData, double time);

/// Writes polygons as VTK_POLYGON cells. xyz holds 3 coordinates [m] per vertex; offsets is CSR with one
/// entry per polygon plus one: polygon k uses vertices [offsets[k], offsets[k+1]), offsets.front() == 0 and
/// offsets.back() == vertex count. Each cellData field holds one tuple per polygon.
void writeVtuPolygons(const std::filesystem::path& path, std::span<const double> xyz,
                      std::span<const std::uint32_t> offsets, const std::vector<VtkField>& cellData, double time);

/// Writes a uniform grid of cells as ImageData (.vti): dims cells per axis (1 for an unused axis), origin and
/// spacing [m]; each cellData field holds one tuple per cell, x fastest.
void writeVtiCells(const std::filesystem::path& path, std::array<int, 3> dims, std::array<double, 3> origin,
                   std::array<double, 3> spacing, const std::vector<VtkField>& cellData, double time);

/// Writes line segments as PolyData (.vtp): xyz holds 6 coordinates per segment (its two ends) [m]; each cellData
/// field one tuple per segment (the contact network: a line per contact).
void writeVtpLines(const std::filesystem::path& path, std::span<const double> xyz,
                   const std::vector<VtkField>& cellData, double time);

/// One planar wall as a quadrilateral (2D walls are passed as thin quads by the caller).
struct WallQuad {
    std::array<std::array<double, 3>, 4> corners{};  ///< [m], in order around the quad
    int id = 0;                                      ///< written as cell data "wall_id"
};

/// Writes the walls as PolyData, one polygon per wall.
void writeVtpWalls(const std::filesystem::path& path, const std::vector<WallQuad>& quads);

/// Walls drawn as lines (segments, arcs) and polygons (plane patches, triangles, tessellated cylinders and discs),
/// each cell with the index of its wall. A cell is a run of point indices: cells [first[k], first[k+1]) of `index`.
struct WallShapes {
    std::vector<std::array<double, 3>> points;  ///< [m]
    std::vector<std::int64_t> lineIndex, lineFirst{0};
    std::vector<std::int32_t> lineWall;
    std::vector<std::int64_t> polyIndex, polyFirst{0};
    std::vector<std::int32_t> polyWall;

    std::int64_t point(double x, double y, double z) {
        points.push_back({x, y, z});
        return static_cast<std::int64_t>(points.size()) - 1;
    }
    void line(std::initializer_list<std::int64_t> ids, int wall) { cell(lineIndex, lineFirst, lineWall, ids, wall); }
    void poly(std::initializer_list<std::int64_t> ids, int wall) { cell(polyIndex, polyFirst, polyWall, ids, wall); }
    void add(const WallQuad& q) {
        std::int64_t ids[4];
        for (int v = 0; v < 4; ++v) ids[v] = point(q.corners[v][0], q.corners[v][1], q.corners[v][2]);
        poly({ids[0], ids[1], ids[2], ids[3]}, q.id);
    }

private:
    static void cell(std::vector<std::int64_t>& index, std::vector<std::int64_t>& first,
                     std::vector<std::int32_t>& wall, std::initializer_list<std::int64_t> ids, int w) {
        index.insert(index.end(), ids.begin(), ids.end());
        first.push_back(static_cast<std::int64_t>(index.size()));
        wall.push_back(w);
    }
};

/// Writes walls of any shape as PolyData (cell data "wall_id"). Throws IoError.
void writeVtpShapes(const std::filesystem::path& path, const WallShapes& shapes);

/// A ParaView .pvd collection. The file is rewritten atomically on construction and on every add(), so a
/// run that stops at any point leaves a valid collection of the snapshots written so far. Each rewrite is
/// O(entries); fine for the thousands of snapshots a run writes.
class PvdCollection {
public:
    /// Starts an empty collection at pvdPath (replacing any previous one). Throws IoError.
    explicit PvdCollection(std::filesystem::path pvdPath);

    /// Adds a file (path relative to the .pvd's directory) at `time` [s]. Several files with the same time
    /// and different `part` numbers form one multi-block timestep (particles, walls). Throws IoError.
    void add(double time, const std::string& relativeFile, int part = 0);

    const std::filesystem::path& path() const { return path_; }
    std::size_t size() const { return entries_.size(); }

    struct Entry {
        double time;
        std::string file;
        int part;
    };
    const std::vector<Entry>& entries() const { return entries_; }
    /// Replaces the entries (a resumed run's, from its checkpoint) and rewrites the file. Throws IoError.
    void assign(std::vector<Entry> entries) {
        entries_ = std::move(entries);
        rewrite();
    }

private:
    void rewrite() const;

    std::filesystem::path path_;
    std::vector<Entry> entries_;
};

}  // namespace haet
