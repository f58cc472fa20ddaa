// bbm io: VTK output of a block assembly (see vtk_output.hpp).
#include "io/vtk_output.hpp"

#include "base/error.hpp"
#include "core/measures.hpp"

// VTK 9.1's type macros end in a stray ';' that -Wpedantic reports in every file;
// CMake passes VTK's directory with -isystem, this keeps a plain -I build quiet too.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkPoints.h>
#include <vtkStringArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>
#pragma GCC diagnostic pop

#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <system_error>

namespace bbm::io {

namespace fs = std::filesystem;
using meshing::BlockAssembly;
using meshing::JointTag;
using PatternKind = meshing::PatternSpec::Kind;

namespace {

// The enum values in order; the names written as field data are indexed by them.
// Extend these lists when the enums grow.
constexpr PatternKind all_pattern_kinds[] = {PatternKind::voronoi,   PatternKind::trigon,
                                             PatternKind::delaunay,  PatternKind::hexagonal,
                                             PatternKind::brick,     PatternKind::single};
constexpr JointTag all_joint_tags[] = {JointTag::inner, JointTag::radial, JointTag::peripheral,
                                       JointTag::real_joint, JointTag::interface, JointTag::fracture};

fs::path tmp_path(const fs::path& file) {
    fs::path t = file;
    t += ".tmp";
    return t;
}

std::string in_quotes(const fs::path& file) { return "'" + file.string() + "'"; }

/// Owns `file`.tmp until commit() renames it over `file`; removes it on any
/// other way out, so a failed write leaves neither debris nor a damaged target.
class TmpFile {
public:
    explicit TmpFile(const fs::path& file) : file_(file), tmp_(tmp_path(file)) {}
    TmpFile(const TmpFile&) = delete;
    TmpFile& operator=(const TmpFile&) = delete;
    ~TmpFile() {
        if (committed_) return;
        std::error_code ec;
        // Only a file we may have written; never a directory that happens to have the name.
        if (fs::is_regular_file(tmp_, ec)) fs::remove(tmp_, ec);
    }
    const fs::path& path() const { return tmp_; }
    void commit() {
        std::error_code ec;
        fs::rename(tmp_, file_, ec); // atomic replacement on POSIX
        if (ec) {
            throw std::runtime_error("cannot write " + in_quotes(file_) + ": rename from " +
                                     in_quotes(tmp_) + " failed: " + ec.message());
        }
        committed_ = true;
    }

private:
    fs::path file_, tmp_;
    bool committed_ = false;
};

/// VTK reports errors through its output window, not the return value alone; an
/// ErrorEvent observer catches the text so the exception can say what went wrong
/// (and the message is not printed twice).
void collect_vtk_error(vtkObject*, unsigned long, void* client, void* call) {
    auto* out = static_cast<std::string*>(client);
    std::string msg = call ? static_cast<const char*>(call) : "";
    // The text is "ERROR: In <source file>, line N\n<class> (<address>): <message>".
    if (const auto p = msg.find("): "); p != std::string::npos) msg.erase(0, p + 3);
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    if (!out->empty()) *out += "; ";
    *out += msg;
}

// Not vtkErrorCode::GetStringFromErrorCode: it lives in VTK::CommonMisc, a library
// this module would link for one function. Codes below FirstVTKErrorCode are errno.
std::string vtk_error_text(unsigned long code) {
    if (code < vtkErrorCode::FirstVTKErrorCode)
        return std::generic_category().message(static_cast<int>(code));
    switch (code) {
    case vtkErrorCode::CannotOpenFileError: return "cannot open the file";
    case vtkErrorCode::OutOfDiskSpaceError: return "out of disk space";
    default: return "VTK error code " + std::to_string(code);
    }
}

void write_grid(vtkUnstructuredGrid* grid, const fs::path& file) {
    TmpFile tmp(file);
    std::string errors;
    vtkNew<vtkCallbackCommand> on_error;
    on_error->SetCallback(collect_vtk_error);
    on_error->SetClientData(&errors);

    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->AddObserver(vtkCommand::ErrorEvent, on_error);
    // The pipeline then adds only "algorithm returned failure", with a dump of its
    // request, to stderr; the exception says it better.
    vtkNew<vtkCallbackCommand> ignore;
    writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, ignore);
    writer->SetFileName(tmp.path().c_str());
    writer->SetInputData(grid);
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff(); // raw binary, not base64
    // LZ4, not zlib: a snapshot of the trigon tunnel takes a quarter of the time
    // (0.8 -> 0.2 s of its 8 s run, serial), for files 30% larger; ParaView and
    // VTK's readers take either.
    writer->SetCompressorTypeToLZ4();
    writer->SetHeaderTypeToUInt64(); // no 4 GiB limit on one array, whatever the model size
    const int ok = writer->Write();
    const unsigned long code = writer->GetErrorCode();
    if (ok != 1 || code != vtkErrorCode::NoError || !errors.empty()) {
        // The writer's own text already says what the code says, and more.
        std::string why = errors;
        if (why.empty() && code != vtkErrorCode::NoError) why = vtk_error_text(code);
        if (why.empty()) why = "vtkXMLUnstructuredGridWriter failed";
        throw std::runtime_error("cannot write " + in_quotes(file) + ": " + why);
    }
    tmp.commit();
}

vtkNew<vtkIntArray> int_array(const char* name, vtkIdType n) {
    vtkNew<vtkIntArray> a;
    a->SetName(name);
    a->SetNumberOfTuples(n);
    return a;
}

vtkNew<vtkDoubleArray> double_array(const char* name, vtkIdType n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfTuples(n);
    return a;
}

template <class Range, class Name>
vtkNew<vtkStringArray> string_array(const char* name, const Range& values, Name&& to_name) {
    vtkNew<vtkStringArray> a;
    a->SetName(name);
    a->SetNumberOfValues(static_cast<vtkIdType>(std::size(values)));
    vtkIdType i = 0;
    for (const auto& v : values) a->SetValue(i++, to_name(v));
    return a;
}

/// Adds cell-data arrays to a grid, in the order given.
template <class... Arrays>
void add_cell_arrays(vtkUnstructuredGrid* grid, Arrays&... arrays) {
    (grid->GetCellData()->AddArray(arrays), ...);
}

void require(bool cond, const fs::path& file, const std::string& what) {
    if (!cond) throw std::invalid_argument("cannot write " + in_quotes(file) + ": " + what);
}

std::string xml_escape(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (const char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        case '\'': out += "&apos;"; break;
        default: out += c;
        }
    }
    return out;
}

/// Shortest text that reads back as the same double, so time steps never merge.
std::string exact_number(double v) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return {buf, r.ptr};
}

} // namespace

void write_blocks_vtu(const BlockAssembly& a, const fs::path& file) {
    // Cheap always-on checks: a short array here would be read out of bounds.
    const std::size_t n = a.region.size();
    require(a.first.size() == n + 1, file, "first has " + std::to_string(a.first.size()) +
                                               " entries for " + std::to_string(n) + " blocks");
    require(a.first.back() == a.points.size(), file, "first.back() != points.size()");
    require(a.pattern.size() == n && a.parent.size() == n && a.area.size() == n, file,
            "pattern, parent and area must have one entry per block");

    // Each block owns its vertices, so point i of the grid is a.points[i] and the
    // cell offsets are `first` itself.
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(static_cast<vtkIdType>(a.points.size()));
    for (std::size_t i = 0; i < a.points.size(); ++i)
        points->SetPoint(static_cast<vtkIdType>(i), a.points[i].x, a.points[i].y, 0.0);

    vtkNew<vtkIdTypeArray> offsets, connectivity;
    offsets->SetNumberOfValues(static_cast<vtkIdType>(a.first.size()));
    for (std::size_t b = 0; b < a.first.size(); ++b)
        offsets->SetValue(static_cast<vtkIdType>(b), static_cast<vtkIdType>(a.first[b]));
    connectivity->SetNumberOfValues(static_cast<vtkIdType>(a.points.size()));
    for (vtkIdType i = 0; i < connectivity->GetNumberOfValues(); ++i) connectivity->SetValue(i, i);
    vtkNew<vtkCellArray> cells;
    cells->SetData(offsets, connectivity);

    vtkNew<vtkUnstructuredGrid> grid;
    grid->SetPoints(points);
    grid->SetCells(VTK_POLYGON, cells);

    const auto nb = static_cast<vtkIdType>(n);
    auto block_id = int_array("block_id", nb);
    auto region = int_array("region", nb);
    auto area = double_array("area", nb);
    auto pattern = int_array("pattern", nb);
    auto parent = int_array("parent", nb);
    for (vtkIdType b = 0; b < nb; ++b) {
        block_id->SetValue(b, static_cast<int>(b));
        region->SetValue(b, a.region[b]);
        area->SetValue(b, a.area[b]);
        pattern->SetValue(b, static_cast<int>(a.pattern[b]));
        parent->SetValue(b, a.parent[b]);
    }
    add_cell_arrays(grid, block_id, region, area, pattern, parent);

    vtkFieldData* fd = grid->GetFieldData();
    fd->AddArray(string_array("pattern_names", all_pattern_kinds,
                              [](PatternKind k) { return meshing::to_string(k); }));
    fd->AddArray(string_array("region_names", a.region_names,
                              [](const std::string& s) { return s; }));

    write_grid(grid, file);
}

void write_joints_vtu(const BlockAssembly& a, const fs::path& file) {
    const auto nj = static_cast<vtkIdType>(a.joints.size());

    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(2 * nj);
    vtkNew<vtkIdTypeArray> offsets, connectivity;
    offsets->SetNumberOfValues(nj + 1);
    connectivity->SetNumberOfValues(2 * nj);
    auto tag = int_array("tag", nj);
    auto block_a = int_array("block_a", nj);
    auto block_b = int_array("block_b", nj);
    auto length = double_array("length", nj);
    for (vtkIdType j = 0; j < nj; ++j) {
        const meshing::JointRecord& r = a.joints[j];
        points->SetPoint(2 * j, r.p0.x, r.p0.y, 0.0);
        points->SetPoint(2 * j + 1, r.p1.x, r.p1.y, 0.0);
        offsets->SetValue(j, 2 * j);
        connectivity->SetValue(2 * j, 2 * j);
        connectivity->SetValue(2 * j + 1, 2 * j + 1);
        tag->SetValue(j, static_cast<int>(r.tag));
        block_a->SetValue(j, r.block_a);
        block_b->SetValue(j, r.block_b);
        length->SetValue(j, r.length());
    }
    offsets->SetValue(nj, 2 * nj);
    vtkNew<vtkCellArray> cells;
    cells->SetData(offsets, connectivity);

    vtkNew<vtkUnstructuredGrid> grid;
    grid->SetPoints(points);
    grid->SetCells(VTK_LINE, cells);
    add_cell_arrays(grid, tag, block_a, block_b, length);
    grid->GetFieldData()->AddArray(
        string_array("tag_names", all_joint_tags, [](JointTag t) { return meshing::to_string(t); }));

    write_grid(grid, file);
}

void write_pvd(const fs::path& file, const std::vector<std::pair<double, std::string>>& steps) {
    std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"";
    xml += std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
    xml += "\">\n  <Collection>\n";
    std::map<double, int> parts_at; // files already listed per time
    for (const auto& [time, path] : steps) {
        require(std::isfinite(time), file, "time of '" + path + "'" + " is not finite");
        const int part = parts_at[time]++;
        xml += "    <DataSet timestep=\"" + exact_number(time) + "\" group=\"\" part=\"" +
               std::to_string(part) + "\" file=\"" + xml_escape(path) + "\"/>\n";
    }
    xml += "  </Collection>\n</VTKFile>\n";
    write_text_atomically(file, xml);
}

void make_output_directory(const fs::path& dir) {
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw InputError("--out", 0, "", dir.string() + " is a file, not a directory");
    fs::create_directories(dir, ec);
    if (ec) throw InputError("--out", 0, "", "cannot create the directory " + dir.string() + ": " + ec.message());
    const fs::path probe = dir / ".bbm-write-probe";
    std::FILE* f = std::fopen(probe.c_str(), "wb");
    if (!f) throw InputError("--out", 0, "", "cannot write in " + dir.string());
    std::fclose(f);
    fs::remove(probe, ec);
}

void write_text_atomically(const fs::path& file, std::string_view text) {
    TmpFile tmp(file);
    std::FILE* f = std::fopen(tmp.path().c_str(), "wb");
    if (!f) {
        throw std::runtime_error("cannot write " + in_quotes(file) + ": " +
                                 std::generic_category().message(errno));
    }
    const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    const int write_errno = errno;
    // fclose flushes: a full disk may show up only here.
    const bool closed = std::fclose(f) == 0;
    if (!written || !closed) {
        throw std::runtime_error("cannot write " + in_quotes(file) + ": " +
                                 std::generic_category().message(written ? errno : write_errno));
    }
    tmp.commit();
}

namespace {

/// The state's cells in one grid: rigid blocks (polygons) first, then the zones
/// of deformable blocks (triangles), with their points' displacement.
void add_state_cells(vtkUnstructuredGrid* grid, const World& w, const std::vector<int>& kept,
                     const std::vector<int>& zones) {
    const auto& x = w.vertices;
    const auto& nodes = w.nodes;
    const auto& z = w.zones;
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    auto point_disp = double_array("displacement", 0);
    point_disp->SetNumberOfComponents(3);
    vtkNew<vtkIdTypeArray> offsets, connectivity;
    vtkNew<vtkUnsignedCharArray> types;
    offsets->InsertNextValue(0);
    for (int i : kept) {
        const Vec2 c0 = w.blocks.centroid0[i];
        for (std::uint32_t v = w.blocks.first[i]; v < w.blocks.first[i + 1]; ++v) {
            connectivity->InsertNextValue(points->InsertNextPoint(x.position[v].x, x.position[v].y, 0.0));
            const Vec2 u = x.position[v] - (c0 + x.local[v]);
            point_disp->InsertNextTuple3(u.x, u.y, 0.0);
        }
        offsets->InsertNextValue(connectivity->GetNumberOfValues());
        types->InsertNextValue(VTK_POLYGON);
    }
    // Nodes of deformable blocks, written once each (only those of kept zones).
    std::vector<vtkIdType> node_point(nodes.count(), -1);
    for (int k : zones) {
        for (int nd : z.node[k]) {
            if (node_point[nd] < 0) {
                node_point[nd] = points->InsertNextPoint(nodes.position[nd].x, nodes.position[nd].y, 0.0);
                const Vec2 u = nodes.position[nd] - nodes.position0[nd];
                point_disp->InsertNextTuple3(u.x, u.y, 0.0);
            }
            connectivity->InsertNextValue(node_point[nd]);
        }
        offsets->InsertNextValue(connectivity->GetNumberOfValues());
        types->InsertNextValue(VTK_TRIANGLE);
    }
    vtkNew<vtkCellArray> cells;
    cells->SetData(offsets, connectivity);
    grid->SetPoints(points);
    grid->SetCells(types, cells);
    grid->GetPointData()->AddArray(point_disp);
}

/// The cell arrays of the state's blocks.vtu, one tuple per cell: the rigid blocks, then the zones.
struct StateCellArrays {
    vtkNew<vtkIntArray> id, region, material, kind;
    vtkNew<vtkDoubleArray> rotation, disp, vel, sig, eps;

    explicit StateCellArrays(vtkIdType n)
        : id(int_array("block_id", n)), region(int_array("region", n)), material(int_array("material", n)),
          kind(int_array("zone", n)), rotation(double_array("rotation", n)), disp(double_array("cell_displacement", 0)),
          vel(double_array("velocity", 0)), sig(double_array("stress", 0)), eps(double_array("strain", 0)) {
        disp->SetNumberOfComponents(3), disp->SetNumberOfTuples(n);
        vel->SetNumberOfComponents(3), vel->SetNumberOfTuples(n);
        sig->SetNumberOfComponents(6), sig->SetNumberOfTuples(n);
        eps->SetNumberOfComponents(6), eps->SetNumberOfTuples(n);
        // Symmetric tensors in VTK's order, named so ParaView offers XX, YY, ... to colour by.
        static const char* tensor[6] = {"XX", "YY", "ZZ", "XY", "YZ", "XZ"};
        for (int k = 0; k < 6; ++k) sig->SetComponentName(k, tensor[k]), eps->SetComponentName(k, tensor[k]);
    }
};

/// The cells 0 .. kept-1: the rigid blocks `kept`, their motion and block-averaged stress.
void set_rigid_block_cells(StateCellArrays& a, const World& w, const std::vector<int>& kept,
                           const std::vector<std::array<double, 3>>& stress) {
    const auto& b = w.blocks;
    const auto nk = static_cast<vtkIdType>(kept.size());
    for (vtkIdType k = 0; k < nk; ++k) {
        const int i = kept[k];
        a.id->SetValue(k, i);
        a.region->SetValue(k, b.region[i]);
        a.material->SetValue(k, b.material[i]);
        a.kind->SetValue(k, 0);
        const auto& body = w.bodies.state[i];
        a.rotation->SetValue(k, body.theta);
        const Vec2 u = body.centroid - b.centroid0[i];
        a.disp->SetTuple3(k, u.x, u.y, 0.0);
        a.vel->SetTuple3(k, body.velocity.x, body.velocity.y, 0.0);
        const double t[6] = {stress[i][0], stress[i][1], 0.0, stress[i][2], 0.0, 0.0};
        a.sig->SetTuple(k, t);
        const double e[6] = {0, 0, 0, 0, 0, 0}; // rigid: the strain lives in the joints
        a.eps->SetTuple(k, e);
    }
}

/// The cells from `first` on: the zones of deformable blocks, their nodes' mean
/// motion, stress and strain.
void set_zone_cells(StateCellArrays& a, const World& w, const std::vector<int>& zones, vtkIdType first) {
    const auto& b = w.blocks;
    const auto& nodes = w.nodes;
    const auto& z = w.zones;
    for (std::size_t q = 0; q < zones.size(); ++q) {
        const vtkIdType k = first + vtkIdType(q);
        const int zi = zones[q], blk = z.block[zi];
        a.id->SetValue(k, blk);
        a.region->SetValue(k, b.region[blk]);
        a.material->SetValue(k, b.material[blk]);
        a.kind->SetValue(k, 1);
        a.rotation->SetValue(k, 0.0);
        Vec2 u{}, v{};
        for (int nd : z.node[zi]) u += (nodes.position[nd] - nodes.position0[nd]) / 3.0, v += nodes.velocity[nd] / 3.0;
        a.disp->SetTuple3(k, u.x, u.y, 0.0);
        a.vel->SetTuple3(k, v.x, v.y, 0.0);
        const auto& st = z.stress[zi];
        // Plane strain: σzz = ν(σxx + σyy) = λ/(2(λ+G)) (σxx + σyy) for a stress from zero.
        const auto& el = z.elasticity[zi];
        const double szz = el.lambda / (2.0 * (el.lambda + el.shear)) * (st[0] + st[1]);
        const double t[6] = {st[0], st[1], szz, st[2], 0.0, 0.0};
        a.sig->SetTuple(k, t);
        const auto& sn = z.strain[zi];
        const double e[6] = {sn[0], sn[1], 0.0, sn[2], 0.0, 0.0};
        a.eps->SetTuple(k, e);
    }
}

/// The dynamic mode's cells: each one's peak speed over the run and the stage (a
/// zone: its fastest node's) and whether it is ejected rock (core/ejecta.hpp).
void add_peak_cells(vtkUnstructuredGrid* grid, const World& w, const std::vector<int>& kept,
                    const std::vector<int>& zones) {
    const auto nk = static_cast<vtkIdType>(kept.size()), n = nk + static_cast<vtkIdType>(zones.size());
    auto run = double_array("peak_speed", n), stage = double_array("stage_peak_speed", n);
    auto ejected = int_array("ejected", n);
    const PeakVelocities& p = *w.peak;
    const Ejecta e = measure_ejecta(w);
    for (vtkIdType k = 0; k < nk; ++k) {
        const int i = kept[k];
        run->SetValue(k, p.block_run[i]), stage->SetValue(k, p.block_stage[i]), ejected->SetValue(k, e.ejected[i]);
    }
    for (std::size_t q = 0; q < zones.size(); ++q) {
        double r = 0.0, s = 0.0;
        for (int nd : w.zones.node[zones[q]]) r = std::max(r, p.node_run[nd]), s = std::max(s, p.node_stage[nd]);
        const vtkIdType k = nk + vtkIdType(q);
        run->SetValue(k, r), stage->SetValue(k, s), ejected->SetValue(k, 0);
    }
    add_cell_arrays(grid, run, stage, ejected);
}

} // namespace

void write_state_blocks_vtu(const World& w, const fs::path& file) {
    const auto& b = w.blocks;
    const auto& z = w.zones;
    const auto stress = block_stresses(w);
    std::vector<int> kept, zones; // the rigid blocks and the zones not removed
    for (int i = 0; i < w.bodies.count(); ++i)
        if (!w.bodies.removed[i] && !b.deformable[i]) kept.push_back(i);
    for (int k = 0; k < z.size(); ++k)
        if (!w.bodies.removed[z.block[k]]) zones.push_back(k);
    vtkNew<vtkUnstructuredGrid> grid;
    add_state_cells(grid, w, kept, zones);
    const auto nk = static_cast<vtkIdType>(kept.size());
    StateCellArrays a(nk + static_cast<vtkIdType>(zones.size()));
    set_rigid_block_cells(a, w, kept, stress);
    set_zone_cells(a, w, zones, nk);
    add_cell_arrays(grid, a.id, a.region, a.material, a.kind, a.disp, a.vel, a.rotation, a.sig, a.eps);
    if (w.peak) add_peak_cells(grid, w, kept, zones);
    grid->GetFieldData()->AddArray(string_array("region_names", w.region_names, [](const std::string& x) { return x; }));
    write_grid(grid, file);
}

void write_state_contacts_vtu(const World& w, const fs::path& file) {
    const auto& c = contacts(w);
    const auto& vertex = w.vertices.position;
    const auto n = static_cast<vtkIdType>(c.size());
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(2 * n);
    vtkNew<vtkIdTypeArray> offsets, connectivity;
    offsets->SetNumberOfValues(n + 1);
    connectivity->SetNumberOfValues(2 * n);
    auto sn = double_array("sn", n), tau = double_array("tau", n), un = double_array("un", n),
         us = double_array("us", n), damage = double_array("damage", n), length = double_array("length", n);
    auto state = int_array("state", n), property = int_array("property", n);
    for (vtkIdType i = 0; i < n; ++i) {
        // The contact's share of the joint: from its vertex along the edge inwards.
        const Vec2 x = vertex[c.vertex_id[i]];
        const int e0 = c.edge_id[i], e1 = contact::next_vertex(w.blocks.first.data(), c.edge_block[i], e0);
        const Vec2 mid = 0.5 * (vertex[e0] + vertex[e1]);
        const Vec2 t = contact::tangent_of(c.normal[i]);
        const Vec2 y = x + (dot(mid - x, t) >= 0 ? 1.0 : -1.0) * c.length[i] * t;
        points->SetPoint(2 * i, x.x, x.y, 0.0);
        points->SetPoint(2 * i + 1, y.x, y.y, 0.0);
        offsets->SetValue(i, 2 * i);
        connectivity->SetValue(2 * i, 2 * i);
        connectivity->SetValue(2 * i + 1, 2 * i + 1);
        const auto& h = c.history[i];
        sn->SetValue(i, h.sn);
        tau->SetValue(i, h.tau);
        un->SetValue(i, h.un);
        us->SetValue(i, h.us);
        damage->SetValue(i, h.damage);
        length->SetValue(i, c.length[i]);
        state->SetValue(i, static_cast<int>(contact::state_of(h)));
        property->SetValue(i, c.property[i]);
    }
    offsets->SetValue(n, 2 * n);
    vtkNew<vtkCellArray> cells;
    cells->SetData(offsets, connectivity);
    vtkNew<vtkUnstructuredGrid> grid;
    grid->SetPoints(points);
    grid->SetCells(VTK_LINE, cells);
    add_cell_arrays(grid, sn, tau, un, us, damage, state, property, length);
    if (w.flow) {
        // Water in the joints: the fluid's pressure on the contact and its pipes' aperture.
        auto pressure = double_array("fluid_pressure", n), aperture = double_array("aperture", n);
        const std::vector<double> a = contact_apertures(*w.flow, c);
        for (vtkIdType i = 0; i < n; ++i) pressure->SetValue(i, c.fluid_pressure[i]), aperture->SetValue(i, a[i]);
        add_cell_arrays(grid, pressure, aperture);
    }
    const std::vector<std::string> states{"intact", "softening", "broken_tension", "broken_shear", "sliding"};
    grid->GetFieldData()->AddArray(string_array("state_names", states, [](const std::string& x) { return x; }));
    grid->GetFieldData()->AddArray(string_array("property_names", w.properties.names, [](const std::string& x) { return x; }));
    write_grid(grid, file);
}

namespace {
/// A grid of line cells between structure nodes (supports, pipes): points at the
/// nodes (z = 0), cell i from ends(i).first to ends(i).second.
template <class Ends>
vtkSmartPointer<vtkUnstructuredGrid> line_grid(const std::vector<Vec2>& nodes, vtkIdType n, Ends&& ends) {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(static_cast<vtkIdType>(nodes.size()));
    for (std::size_t k = 0; k < nodes.size(); ++k) points->SetPoint(vtkIdType(k), nodes[k].x, nodes[k].y, 0.0);
    vtkNew<vtkIdTypeArray> offsets, connectivity;
    offsets->SetNumberOfValues(n + 1);
    connectivity->SetNumberOfValues(2 * n);
    for (vtkIdType i = 0; i < n; ++i) {
        const auto [a, b] = ends(i);
        offsets->SetValue(i, 2 * i);
        connectivity->SetValue(2 * i, a);
        connectivity->SetValue(2 * i + 1, b);
    }
    offsets->SetValue(n, 2 * n);
    vtkNew<vtkCellArray> cells;
    cells->SetData(offsets, connectivity);
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    grid->SetPoints(points);
    grid->SetCells(VTK_LINE, cells);
    return grid;
}
} // namespace

void write_flow_vtu(const World& w, const fs::path& file) {
    const JointFlow& flow = *w.flow;
    const auto& net = flow.net;
    const auto& st = flow.state;
    const auto nd = static_cast<vtkIdType>(net.domains()), np = static_cast<vtkIdType>(net.pipes());
    auto grid = line_grid(net.domain_position, np, [&](vtkIdType k) {
        return std::pair<vtkIdType, vtkIdType>{net.pipe_from[k], net.pipe_to[k]};
    });
    auto pressure = double_array("pressure", nd), head = double_array("head", nd);
    auto held = int_array("held", nd), drained = int_array("drained", nd);
    const double rho_g = flow.fluid.density * norm(flow.fluid.gravity);
    for (vtkIdType d = 0; d < nd; ++d) {
        pressure->SetValue(d, st.pressure[d]);
        head->SetValue(d, rho_g > 0 ? net.domain_position[d].y + st.pressure[d] / rho_g : 0.0);
        held->SetValue(d, st.held[d]), drained->SetValue(d, flow.drained[d]);
    }
    auto aperture = double_array("aperture", np), rate = double_array("flow_rate", np);
    auto joint = int_array("joint", np);
    const std::vector<double> q = flow::pipe_flows(net, flow.fluid, st);
    for (vtkIdType k = 0; k < np; ++k) {
        aperture->SetValue(k, flow::hydraulic_aperture(flow.fluid, st.aperture[k]));
        rate->SetValue(k, q[k]);
        joint->SetValue(k, net.pipe_joint[k]);
    }
    add_cell_arrays(grid.GetPointer(), aperture, rate, joint);
    for (auto* a : {static_cast<vtkDataArray*>(pressure), static_cast<vtkDataArray*>(head),
                    static_cast<vtkDataArray*>(held), static_cast<vtkDataArray*>(drained)})
        grid->GetPointData()->AddArray(a);
    write_grid(grid, file);
}

void write_support_vtu(const SupportLines& lines, const fs::path& file) {
    const auto n = static_cast<vtkIdType>(lines.cells.size());
    auto grid = line_grid(lines.points, n, [&](vtkIdType i) {
        return std::pair<vtkIdType, vtkIdType>{lines.cells[i][0], lines.cells[i][1]};
    });
    auto add = [](vtkDataSetAttributes* data, const SupportLines::Array& array) {
        const auto size = static_cast<vtkIdType>(array.values.size());
        if (array.integer) {
            auto a = int_array(array.name.c_str(), size);
            for (vtkIdType i = 0; i < size; ++i) a->SetValue(i, int(array.values[i]));
            data->AddArray(a);
        } else {
            auto a = double_array(array.name.c_str(), size);
            for (vtkIdType i = 0; i < size; ++i) a->SetValue(i, array.values[i]);
            data->AddArray(a);
        }
    };
    for (const auto& array : lines.cell_data) add(grid->GetCellData(), array);
    for (const auto& array : lines.point_data) add(grid->GetPointData(), array);
    for (const auto& [name, values] : lines.names)
        grid->GetFieldData()->AddArray(string_array(name.c_str(), values, [](const std::string& x) { return x; }));
    write_grid(grid, file);
}

void write_events_vtu(const std::vector<SeismicEvent>& events, const fs::path& file) {
    // One vertex cell per event at its position, its figures as cell data.
    const auto n = static_cast<vtkIdType>(events.size());
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    vtkNew<vtkIdTypeArray> offsets, connectivity;
    offsets->SetNumberOfValues(n + 1);
    connectivity->SetNumberOfValues(n);
    auto mw = double_array("mw", n), m0 = double_array("m0", n), r = double_array("r_value", n),
         time = double_array("time", n), energy = double_array("kinetic_energy", n),
         fracture = double_array("fracture_energy", n), length = double_array("length", n);
    auto type = int_array("type", n), bonds = int_array("bonds", n), step = int_array("step", n);
    for (vtkIdType i = 0; i < n; ++i) {
        const SeismicEvent& e = events[std::size_t(i)];
        points->SetPoint(i, e.position.x, e.position.y, 0.0);
        offsets->SetValue(i, i);
        connectivity->SetValue(i, i);
        mw->SetValue(i, e.magnitude), m0->SetValue(i, e.moment_nm), r->SetValue(i, e.r_value);
        time->SetValue(i, e.time), energy->SetValue(i, e.energy), fracture->SetValue(i, e.fracture_energy);
        length->SetValue(i, e.length);
        type->SetValue(i, e.type == "tensile" ? 1 : e.type == "implosive" ? -1 : 0);
        bonds->SetValue(i, e.bonds), step->SetValue(i, int(e.step));
    }
    offsets->SetValue(n, n);
    vtkNew<vtkCellArray> cells;
    cells->SetData(offsets, connectivity);
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    grid->SetPoints(points);
    grid->SetCells(VTK_VERTEX, cells);
    add_cell_arrays(grid, mw, m0, r, time, energy, fracture, length, type, bonds, step);
    write_grid(grid, file);
}

void write_fractures_vtu(const meshing::BlockAssembly& a, const fs::path& file) {
    const auto n = static_cast<vtkIdType>(a.fracture_traces.size());
    std::vector<Vec2> ends;
    ends.reserve(2 * a.fracture_traces.size());
    for (const auto& t : a.fracture_traces) ends.push_back(t.a), ends.push_back(t.b);
    auto grid = line_grid(ends, n, [](vtkIdType i) { return std::pair<vtkIdType, vtkIdType>{2 * i, 2 * i + 1}; });
    auto set = int_array("set", n), region = int_array("region", n);
    auto length = double_array("length", n);
    for (vtkIdType i = 0; i < n; ++i) {
        const int s = a.fracture_trace_set[i];
        set->SetValue(i, s);
        region->SetValue(i, a.fracture_sets[s].region);
        length->SetValue(i, norm(a.fracture_traces[i].b - a.fracture_traces[i].a));
    }
    add_cell_arrays(grid, set, region, length);
    grid->GetFieldData()->AddArray(
        string_array("set_names", a.fracture_sets, [](const meshing::BlockAssembly::FractureSet& s) { return s.name; }));
    write_grid(grid, file);
}

} // namespace bbm::io
