#include "io/vtk.hpp"

#include <fmt/format.h>

#include <bit>
#include <memory>
#include <stdexcept>
#include <string_view>

#include "io/atomic_file.hpp"

namespace haet {

namespace {

// The raw blocks are the in-memory bytes; files declare LittleEndian.
static_assert(std::endian::native == std::endian::little, "VTK raw output assumes a little-endian host");

constexpr std::uint8_t kVtkVertex = 1;  // VTK cell type ids (vtkCellType.h)
constexpr std::uint8_t kVtkPolygon = 7;

const char* typeName(VtkField::Type t) {
    switch (t) {
        case VtkField::Float64:
            return "Float64";
        case VtkField::Int32:
            return "Int32";
        case VtkField::Int64:
            return "Int64";
        case VtkField::UInt8:
            return "UInt8";
    }
    throw std::invalid_argument("VtkField: unknown type");
}

std::size_t typeSize(VtkField::Type t) {
    switch (t) {
        case VtkField::Float64:
            return 8;
        case VtkField::Int32:
            return 4;
        case VtkField::Int64:
            return 8;
        case VtkField::UInt8:
            return 1;
    }
    throw std::invalid_argument("VtkField: unknown type");
}

std::string xmlEscape(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&apos;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

// The arrays of one VTK XML file. The head is built first, with each array's offset into the appended
// section; write() then streams the blocks from where they already are in memory.
class AppendedArrays {
public:
    /// Declares an array of `tuples` tuples and returns its <DataArray/> tag line. `extra` holds further
    /// attributes, with a leading space.
    std::string tag(std::string_view name, VtkField::Type type, int components, std::size_t tuples, const void* data,
                    int indent, std::string_view extra = {}) {
        if (components < 1) throw std::invalid_argument(fmt::format("VTK array '{}': components < 1", name));
        if (tuples > 0 && data == nullptr) throw std::invalid_argument(fmt::format("VTK array '{}': no data", name));
        const std::uint64_t bytes = tuples * static_cast<std::size_t>(components) * typeSize(type);
        std::string line = fmt::format(
            "{:{}}<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"{} format=\"appended\" offset=\"{}\"/>\n",
            "", indent, typeName(type), xmlEscape(name), components, extra, next_);
        blocks_.push_back({data, bytes});
        next_ += sizeof(std::uint64_t) + bytes;
        return line;
    }

    std::string fields(const std::vector<VtkField>& fs, std::size_t tuples, int indent) {
        std::string out;
        for (const VtkField& f : fs) {
            if (f.name.empty()) throw std::invalid_argument("VTK field without a name");
            out += tag(f.name, f.type, f.components, tuples, f.data, indent);
        }
        return out;
    }

    /// Keeps an array built for this file (connectivity, cell types) alive until write().
    template <class T>
    const T* keep(std::vector<T> v) {
        auto owned = std::make_shared<std::vector<T>>(std::move(v));
        owned_.push_back(owned);
        return owned->data();
    }

    void write(const std::filesystem::path& path, std::string_view head) const {
        AtomicOfstream out(path);
        out.write(head.data(), head.size());
        constexpr std::string_view open = "  <AppendedData encoding=\"raw\">\n   _";
        constexpr std::string_view close = "\n  </AppendedData>\n</VTKFile>\n";
        out.write(open.data(), open.size());
        for (const Block& b : blocks_) {
            out.write(&b.bytes, sizeof b.bytes);
            if (b.bytes > 0) out.write(b.data, b.bytes);
        }
        out.write(close.data(), close.size());
        out.commit();
    }

private:
    struct Block {
        const void* data;
        std::uint64_t bytes;
    };
    std::vector<Block> blocks_;
    std::vector<std::shared_ptr<const void>> owned_;
    std::uint64_t next_ = 0;
};

std::string fileHead(std::string_view type) {
    return fmt::format(
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"{}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        type);
}

// VTK's reader needs NumberOfTuples on FieldData arrays (there is no point or cell count to go by).
std::string timeValue(AppendedArrays& arrays, const double* time) {
    return "    <FieldData>\n" + arrays.tag("TimeValue", VtkField::Float64, 1, 1, time, 6, " NumberOfTuples=\"1\"") +
           "    </FieldData>\n";
}

// An UnstructuredGrid whose cells are given by VTK's own CSR: cell k ends at cellEnd[k] in connectivity.
void writeUnstructured(const std::filesystem::path& path, std::size_t nPoints, const double* xyz,
                       std::vector<std::int64_t> connectivity, std::vector<std::int64_t> cellEnd,
                       std::vector<std::uint8_t> types, const std::vector<VtkField>& pointData,
                       const std::vector<VtkField>& cellData, double time) {
    const std::size_t nCells = types.size();
    AppendedArrays arrays;
    std::string head = fileHead("UnstructuredGrid");
    head += "  <UnstructuredGrid>\n";
    head += timeValue(arrays, &time);
    head += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", nPoints, nCells);
    head += "      <PointData>\n" + arrays.fields(pointData, nPoints, 8) + "      </PointData>\n";
    head += "      <CellData>\n" + arrays.fields(cellData, nCells, 8) + "      </CellData>\n";
    head += "      <Points>\n" + arrays.tag("Points", VtkField::Float64, 3, nPoints, xyz, 8) + "      </Points>\n";
    head += "      <Cells>\n";
    const std::size_t nConn = connectivity.size();
    head += arrays.tag("connectivity", VtkField::Int64, 1, nConn, arrays.keep(std::move(connectivity)), 8);
    head += arrays.tag("offsets", VtkField::Int64, 1, nCells, arrays.keep(std::move(cellEnd)), 8);
    head += arrays.tag("types", VtkField::UInt8, 1, nCells, arrays.keep(std::move(types)), 8);
    head += "      </Cells>\n";
    head += "    </Piece>\n";
    head += "  </UnstructuredGrid>\n";
    arrays.write(path, head);
}

}  // namespace

void writeVtuPoints(const std::filesystem::path& path, std::size_t n, const double* xyz,
                    const std::vector<VtkField>& pointData, double time) {
    std::vector<std::int64_t> connectivity(n), cellEnd(n);
    for (std::size_t i = 0; i < n; ++i) {
        connectivity[i] = static_cast<std::int64_t>(i);
        cellEnd[i] = static_cast<std::int64_t>(i + 1);
    }
    writeUnstructured(path, n, xyz, std::move(connectivity), std::move(cellEnd),
                      std::vector<std::uint8_t>(n, kVtkVertex), pointData, {}, time);
}

void writeVtuPolygons(const std::filesystem::path& path, std::span<const double> xyz,
                      std::span<const std::uint32_t> offsets, const std::vector<VtkField>& cellData, double time) {
    if (xyz.size() % 3 != 0) throw std::invalid_argument("writeVtuPolygons: xyz size is not a multiple of 3");
    const std::size_t nVertices = xyz.size() / 3;
    const std::size_t nPolygons = offsets.empty() ? 0 : offsets.size() - 1;
    if (!offsets.empty() && (offsets.front() != 0 || offsets.back() != nVertices))
        throw std::invalid_argument(
            fmt::format("writeVtuPolygons: offsets must run from 0 to the vertex count {} (got {}..{})", nVertices,
                        offsets.front(), offsets.back()));
    std::vector<std::int64_t> connectivity(nVertices), cellEnd(nPolygons);
    for (std::size_t i = 0; i < nVertices; ++i) connectivity[i] = static_cast<std::int64_t>(i);
    for (std::size_t k = 0; k < nPolygons; ++k) {
        if (offsets[k + 1] < offsets[k] + 3)
            throw std::invalid_argument(fmt::format("writeVtuPolygons: polygon {} has fewer than 3 vertices", k));
        cellEnd[k] = offsets[k + 1];
    }
    writeUnstructured(path, nVertices, xyz.data(), std::move(connectivity), std::move(cellEnd),
                      std::vector<std::uint8_t>(nPolygons, kVtkPolygon), {}, cellData, time);
}

void writeVtpWalls(const std::filesystem::path& path, const std::vector<WallQuad>& quads) {
    WallShapes sh;
    for (const WallQuad& q : quads) sh.add(q);
    writeVtpShapes(path, sh);
}

void writeVtpShapes(const std::filesystem::path& path, const WallShapes& sh) {
    const std::size_t np = sh.points.size(), nl = sh.lineWall.size(), npoly = sh.polyWall.size();
    std::vector<double> xyz;
    xyz.reserve(3 * np);
    for (const auto& p : sh.points) xyz.insert(xyz.end(), p.begin(), p.end());
    // Cell data runs over verts, lines, polys, strips in that order.
    std::vector<std::int32_t> ids(sh.lineWall);
    ids.insert(ids.end(), sh.polyWall.begin(), sh.polyWall.end());
    AppendedArrays arrays;
    std::string head = fileHead("PolyData");
    head += "  <PolyData>\n";
    head += fmt::format(
        "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" "
        "NumberOfPolys=\"{}\">\n",
        np, nl, npoly);
    head += "      <CellData>\n" +
            arrays.tag("wall_id", VtkField::Int32, 1, nl + npoly, arrays.keep(std::move(ids)), 8) +
            "      </CellData>\n";
    head += "      <Points>\n" + arrays.tag("Points", VtkField::Float64, 3, np, arrays.keep(std::move(xyz)), 8) +
            "      </Points>\n";
    auto cells = [&](const char* tagName, const std::vector<std::int64_t>& index,
                     const std::vector<std::int64_t>& first) {
        head += fmt::format("      <{}>\n", tagName);
        head += arrays.tag("connectivity", VtkField::Int64, 1, index.size(), index.data(), 8);
        head += arrays.tag("offsets", VtkField::Int64, 1, first.size() - 1, first.data() + 1, 8);
        head += fmt::format("      </{}>\n", tagName);
    };
    cells("Lines", sh.lineIndex, sh.lineFirst);
    cells("Polys", sh.polyIndex, sh.polyFirst);
    head += "    </Piece>\n";
    head += "  </PolyData>\n";
    arrays.write(path, head);
}

void writeVtpLines(const std::filesystem::path& path, std::span<const double> xyz,
                   const std::vector<VtkField>& cellData, double time) {
    const std::size_t np = xyz.size() / 3, nl = np / 2;
    std::vector<std::int64_t> index(np), end(nl);
    for (std::size_t k = 0; k < np; ++k) index[k] = static_cast<std::int64_t>(k);
    for (std::size_t k = 0; k < nl; ++k) end[k] = static_cast<std::int64_t>(2 * k + 2);
    AppendedArrays arrays;
    std::string head = fileHead("PolyData");
    head += "  <PolyData>\n";
    head += timeValue(arrays, arrays.keep(std::vector<double>{time}));
    head += fmt::format(
        "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" "
        "NumberOfPolys=\"0\">\n",
        np, nl);
    head += "      <CellData>\n" + arrays.fields(cellData, nl, 8) + "      </CellData>\n";
    head += "      <Points>\n" + arrays.tag("Points", VtkField::Float64, 3, np, xyz.data(), 8) + "      </Points>\n";
    head += "      <Lines>\n";
    head += arrays.tag("connectivity", VtkField::Int64, 1, np, arrays.keep(std::move(index)), 8);
    head += arrays.tag("offsets", VtkField::Int64, 1, nl, arrays.keep(std::move(end)), 8);
    head += "      </Lines>\n";
    head += "    </Piece>\n";
    head += "  </PolyData>\n";
    arrays.write(path, head);
}

void writeVtiCells(const std::filesystem::path& path, std::array<int, 3> dims, std::array<double, 3> origin,
                   std::array<double, 3> spacing, const std::vector<VtkField>& cellData, double time) {
    std::size_t n = 1;
    for (int d : dims) {
        if (d < 1) throw std::invalid_argument("VTK image: every axis needs at least one cell");
        n *= static_cast<std::size_t>(d);
    }
    AppendedArrays arrays;
    const std::string extent = fmt::format("0 {} 0 {} 0 {}", dims[0], dims[1], dims[2]);
    std::string head = fileHead("ImageData");
    head += fmt::format("  <ImageData WholeExtent=\"{}\" Origin=\"{} {} {}\" Spacing=\"{} {} {}\">\n", extent,
                        origin[0], origin[1], origin[2], spacing[0], spacing[1], spacing[2]);
    head += timeValue(arrays, arrays.keep(std::vector<double>{time}));
    head += fmt::format("    <Piece Extent=\"{}\">\n", extent);
    head += "      <CellData>\n" + arrays.fields(cellData, n, 8) + "      </CellData>\n";
    head += "    </Piece>\n";
    head += "  </ImageData>\n";
    arrays.write(path, head);
}

PvdCollection::PvdCollection(std::filesystem::path pvdPath) : path_(std::move(pvdPath)) { rewrite(); }

void PvdCollection::add(double time, const std::string& relativeFile, int part) {
    entries_.push_back({time, relativeFile, part});
    rewrite();
}

void PvdCollection::rewrite() const {
    std::string text =
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        "  <Collection>\n";
    for (const Entry& e : entries_)
        text += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"{}\" file=\"{}\"/>\n", e.time, e.part,
                            xmlEscape(e.file));
    text += "  </Collection>\n</VTKFile>\n";
    writeFileAtomic(path_, text);
}

}  // namespace haet
