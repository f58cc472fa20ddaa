// Tests of io/vtk_output: what is written is read back by VTK's own reader and
// compared with the hand-built assembly, value by value; the atomic writers leave
// either the new file or the old one, never a .tmp.
#include "io/picture.hpp"
#include "io/vtk_output.hpp"

#include <doctest/doctest.h>
#include <png.h>

// VTK 9.1's type macros end in a stray ';' that -Wpedantic reports (see vtk_output.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLUnstructuredGridReader.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;
using namespace bbm;
using meshing::BlockAssembly;
using meshing::JointTag;
using PatternKind = meshing::PatternSpec::Kind;

namespace {

/// A fresh directory under the system temp directory, removed with its content.
struct TempDir {
    fs::path path;
    TempDir() {
        std::random_device rd;
        std::ostringstream name;
        name << "bbm_test_output_" << std::hex << rd() << rd();
        path = fs::temp_directory_path() / name.str();
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
};

/// Two blocks side by side, a unit square and a 1.5 x 1 rectangle, in two regions;
/// their shared edge x = 1 is split at y = 0.4 into two joints of different tags.
BlockAssembly two_blocks() {
    BlockAssembly a;
    a.points = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {1, 0}, {2.5, 0}, {2.5, 1}, {1, 1}};
    a.first = {0, 4, 8};
    a.region = {0, 1};
    a.pattern = {PatternKind::voronoi, PatternKind::brick};
    a.parent = {0, 7};
    a.area = {1.0, 1.5};
    a.region_names = {"rock", "lining"};
    a.region_size = {0.5, 0.25};
    meshing::JointRecord j0;
    j0.block_a = 0;
    j0.block_b = 1;
    j0.edge_a = 1;
    j0.edge_b = 3;
    j0.p0 = {1, 0};
    j0.p1 = {1, 0.4};
    j0.tag = JointTag::real_joint;
    meshing::JointRecord j1 = j0;
    j1.p0 = {1, 0.4};
    j1.p1 = {1, 1};
    j1.tag = JointTag::interface;
    a.joints = {j0, j1};
    return a;
}

vtkSmartPointer<vtkUnstructuredGrid> read_vtu(const fs::path& file) {
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->SetFileName(file.c_str());
    reader->Update();
    REQUIRE(reader->GetErrorCode() == 0);
    return reader->GetOutput();
}

std::string slurp(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// The message of the std::runtime_error `f` throws, or "" if it throws none.
template <class F>
std::string runtime_error_of(F&& f) {
    try {
        f();
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}

fs::path with_tmp(const fs::path& file) {
    fs::path t = file;
    t += ".tmp";
    return t;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// VTK prints its own error text for expected failures; keep the test log clean.
struct QuietVtk {
    QuietVtk() { vtkObject::GlobalWarningDisplayOff(); }
    ~QuietVtk() { vtkObject::GlobalWarningDisplayOn(); }
};

} // namespace

TEST_CASE("blocks.vtu: one polygon per block, its points and its cell data") {
    TempDir dir;
    const BlockAssembly a = two_blocks();
    const fs::path file = dir.path / "blocks.vtu";
    io::write_blocks_vtu(a, file);
    CHECK_FALSE(fs::exists(with_tmp(file)));

    const auto grid = read_vtu(file);
    REQUIRE(grid->GetNumberOfCells() == 2);
    REQUIRE(grid->GetNumberOfPoints() == 8);
    for (int b = 0; b < 2; ++b) {
        CAPTURE(b);
        CHECK(grid->GetCellType(b) == VTK_POLYGON);
        vtkIdType n = 0;
        const vtkIdType* ids = nullptr;
        grid->GetCellPoints(b, n, ids);
        REQUIRE(n == 4);
        const auto poly = a.block(b);
        for (vtkIdType k = 0; k < n; ++k) {
            double p[3];
            grid->GetPoint(ids[k], p);
            CHECK(p[0] == poly[k].x); // doubles written as Float64: exact
            CHECK(p[1] == poly[k].y);
            CHECK(p[2] == 0.0);
        }
    }

    vtkCellData* cd = grid->GetCellData();
    const auto int_values = [&](const char* name) {
        vtkDataArray* arr = cd->GetArray(name);
        REQUIRE_MESSAGE(arr != nullptr, name);
        CHECK_MESSAGE(arr->GetDataType() == VTK_INT, name);
        REQUIRE(arr->GetNumberOfTuples() == 2);
        return std::vector<int>{static_cast<int>(arr->GetTuple1(0)), static_cast<int>(arr->GetTuple1(1))};
    };
    CHECK(int_values("block_id") == std::vector<int>{0, 1});
    CHECK(int_values("region") == std::vector<int>{0, 1});
    CHECK(int_values("parent") == std::vector<int>{0, 7});
    CHECK(int_values("pattern") ==
          std::vector<int>{static_cast<int>(PatternKind::voronoi), static_cast<int>(PatternKind::brick)});
    vtkDataArray* area = cd->GetArray("area");
    REQUIRE(area != nullptr);
    CHECK(area->GetDataType() == VTK_DOUBLE);
    CHECK(area->GetTuple1(0) == 1.0);
    CHECK(area->GetTuple1(1) == 1.5);

    auto* pattern_names = vtkStringArray::SafeDownCast(grid->GetFieldData()->GetAbstractArray("pattern_names"));
    REQUIRE(pattern_names != nullptr);
    REQUIRE(pattern_names->GetNumberOfValues() == static_cast<int>(PatternKind::single) + 1);
    for (int k = 0; k <= static_cast<int>(PatternKind::single); ++k)
        CHECK(pattern_names->GetValue(k) == meshing::to_string(static_cast<PatternKind>(k)));
    auto* region_names = vtkStringArray::SafeDownCast(grid->GetFieldData()->GetAbstractArray("region_names"));
    REQUIRE(region_names != nullptr);
    REQUIRE(region_names->GetNumberOfValues() == 2);
    CHECK(region_names->GetValue(0) == "rock");
    CHECK(region_names->GetValue(1) == "lining");
}

TEST_CASE("joints.vtu: one line per joint, with tag, blocks and length") {
    TempDir dir;
    const BlockAssembly a = two_blocks();
    const fs::path file = dir.path / "joints.vtu";
    io::write_joints_vtu(a, file);
    CHECK_FALSE(fs::exists(with_tmp(file)));

    const auto grid = read_vtu(file);
    REQUIRE(grid->GetNumberOfCells() == 2);
    for (int j = 0; j < 2; ++j) {
        CAPTURE(j);
        CHECK(grid->GetCellType(j) == VTK_LINE);
        vtkIdType n = 0;
        const vtkIdType* ids = nullptr;
        grid->GetCellPoints(j, n, ids);
        REQUIRE(n == 2);
        double p[3], q[3];
        grid->GetPoint(ids[0], p);
        grid->GetPoint(ids[1], q);
        CHECK(p[0] == a.joints[j].p0.x);
        CHECK(p[1] == a.joints[j].p0.y);
        CHECK(q[0] == a.joints[j].p1.x);
        CHECK(q[1] == a.joints[j].p1.y);
        CHECK(p[2] == 0.0);
        CHECK(q[2] == 0.0);
    }
    vtkCellData* cd = grid->GetCellData();
    for (const char* name : {"tag", "block_a", "block_b"}) {
        REQUIRE_MESSAGE(cd->GetArray(name) != nullptr, name);
        CHECK_MESSAGE(cd->GetArray(name)->GetDataType() == VTK_INT, name);
    }
    CHECK(cd->GetArray("tag")->GetTuple1(0) == static_cast<int>(JointTag::real_joint));
    CHECK(cd->GetArray("tag")->GetTuple1(1) == static_cast<int>(JointTag::interface));
    CHECK(cd->GetArray("block_a")->GetTuple1(1) == 0);
    CHECK(cd->GetArray("block_b")->GetTuple1(1) == 1);
    vtkDataArray* length = cd->GetArray("length");
    REQUIRE(length != nullptr);
    CHECK(length->GetDataType() == VTK_DOUBLE);
    CHECK(length->GetTuple1(0) == doctest::Approx(0.4).epsilon(1e-15));
    CHECK(length->GetTuple1(1) == doctest::Approx(0.6).epsilon(1e-15));

    auto* tag_names = vtkStringArray::SafeDownCast(grid->GetFieldData()->GetAbstractArray("tag_names"));
    REQUIRE(tag_names != nullptr);
    REQUIRE(tag_names->GetNumberOfValues() == static_cast<int>(JointTag::fracture) + 1);
    for (int k = 0; k <= static_cast<int>(JointTag::interface); ++k)
        CHECK(tag_names->GetValue(k) == meshing::to_string(static_cast<JointTag>(k)));
}

TEST_CASE("the .vtu files are appended raw binary, LZ4-compressed") {
    TempDir dir;
    const BlockAssembly a = two_blocks();
    io::write_blocks_vtu(a, dir.path / "blocks.vtu");
    io::write_joints_vtu(a, dir.path / "joints.vtu");
    for (const char* name : {"blocks.vtu", "joints.vtu"}) {
        CAPTURE(name);
        const std::string text = slurp(dir.path / name);
        CHECK(contains(text, "compressor=\"vtkLZ4DataCompressor\""));
        CHECK(contains(text, "format=\"appended\""));
        CHECK(contains(text, "<AppendedData encoding=\"raw\">"));
        CHECK_FALSE(contains(text, "format=\"ascii\""));
    }
}

TEST_CASE("an empty assembly gives empty but readable files") {
    TempDir dir;
    const BlockAssembly empty;
    io::write_blocks_vtu(empty, dir.path / "blocks.vtu");
    io::write_joints_vtu(empty, dir.path / "joints.vtu");
    CHECK(read_vtu(dir.path / "blocks.vtu")->GetNumberOfCells() == 0);
    CHECK(read_vtu(dir.path / "joints.vtu")->GetNumberOfCells() == 0);
}

TEST_CASE("an inconsistent assembly is refused before anything is written") {
    TempDir dir;
    BlockAssembly a = two_blocks();
    a.area.pop_back();
    CHECK_THROWS_AS(io::write_blocks_vtu(a, dir.path / "blocks.vtu"), std::invalid_argument);
    a = two_blocks();
    a.first.back() = 7;
    CHECK_THROWS_AS(io::write_blocks_vtu(a, dir.path / "blocks.vtu"), std::invalid_argument);
    CHECK(fs::is_empty(dir.path));
}

TEST_CASE("a failed .vtu write throws naming the file and keeps the earlier file") {
    TempDir dir;
    QuietVtk quiet;
    const BlockAssembly a = two_blocks();

    const fs::path missing = dir.path / "no_such_dir" / "blocks.vtu";
    const std::string msg = runtime_error_of([&] { io::write_blocks_vtu(a, missing); });
    CHECK(contains(msg, missing.string()));

    // An earlier good file, then a write that cannot create its .tmp (a directory
    // has taken the name): the exception names the file, the old content survives.
    const fs::path file = dir.path / "blocks.vtu";
    io::write_blocks_vtu(a, file);
    const std::string before = slurp(file);
    fs::create_directory(with_tmp(file));
    BlockAssembly b = two_blocks();
    b.area = {2.0, 3.0};
    const std::string msg2 = runtime_error_of([&] { io::write_blocks_vtu(b, file); });
    CHECK(contains(msg2, file.string()));
    CHECK(slurp(file) == before);
    CHECK(read_vtu(file)->GetCellData()->GetArray("area")->GetTuple1(0) == 1.0);
    CHECK(fs::is_directory(with_tmp(file))); // not ours to delete
}

TEST_CASE("write_text_atomically replaces the content and leaves no .tmp") {
    TempDir dir;
    const fs::path file = dir.path / "summary.json";
    io::write_text_atomically(file, "{\"blocks\": 1}\n");
    CHECK(slurp(file) == "{\"blocks\": 1}\n");
    io::write_text_atomically(file, "{}");
    CHECK(slurp(file) == "{}");
    CHECK_FALSE(fs::exists(with_tmp(file)));
    io::write_text_atomically(file, "");
    CHECK(fs::file_size(file) == 0);

    SUBCASE("a failed write throws naming the file and keeps the old content") {
        io::write_text_atomically(file, "old");
        fs::create_directory(with_tmp(file));
        const std::string msg = runtime_error_of([&] { io::write_text_atomically(file, "new"); });
        CHECK(contains(msg, file.string()));
        CHECK(slurp(file) == "old");
    }
    SUBCASE("a missing directory is reported with the file name") {
        const fs::path missing = dir.path / "nope" / "summary.json";
        CHECK(contains(runtime_error_of([&] { io::write_text_atomically(missing, "x"); }), missing.string()));
    }
}

TEST_CASE("write_pvd names each file with its time step") {
    TempDir dir;
    const fs::path file = dir.path / "series.pvd";
    io::write_pvd(file, {{0.0, "step_0000/blocks.vtu"},
                         {0.1, "step_0001/blocks.vtu"},
                         {0.1, "step_0001/joints.vtu"},
                         {2.5e-7, "odd & <name>.vtu"}});
    CHECK_FALSE(fs::exists(with_tmp(file)));

    vtkNew<vtkXMLDataParser> parser;
    parser->SetFileName(file.c_str());
    REQUIRE(parser->Parse() == 1); // well-formed XML
    vtkXMLDataElement* root = parser->GetRootElement();
    REQUIRE(root != nullptr);
    CHECK(std::string(root->GetName()) == "VTKFile");
    CHECK(std::string(root->GetAttribute("type")) == "Collection");
    vtkXMLDataElement* collection = root->FindNestedElementWithName("Collection");
    REQUIRE(collection != nullptr);
    REQUIRE(collection->GetNumberOfNestedElements() == 4);

    struct Expected {
        double time;
        int part;
        const char* file;
    };
    const Expected expected[] = {{0.0, 0, "step_0000/blocks.vtu"},
                                 {0.1, 0, "step_0001/blocks.vtu"},
                                 {0.1, 1, "step_0001/joints.vtu"},
                                 {2.5e-7, 0, "odd & <name>.vtu"}};
    for (int i = 0; i < 4; ++i) {
        CAPTURE(i);
        vtkXMLDataElement* ds = collection->GetNestedElement(i);
        CHECK(std::string(ds->GetName()) == "DataSet");
        CHECK(std::string(ds->GetAttribute("file")) == expected[i].file);
        // Written as the shortest exact text: the time reads back bit for bit.
        CHECK(std::stod(ds->GetAttribute("timestep")) == expected[i].time);
        CHECK(std::stoi(ds->GetAttribute("part")) == expected[i].part);
    }

    CHECK_THROWS_AS(io::write_pvd(file, {{std::nan(""), "x.vtu"}}), std::invalid_argument);
    CHECK(contains(slurp(file), "step_0001/joints.vtu")); // the refused write left the old file
}

TEST_CASE("a plot with nothing to draw on its log axis is written (a run stopped at its first record)") {
    // A run stopped by a signal at its first history record has one ratio, 0,
    // which a log axis leaves out: the bounds stayed infinite and the tick loop
    // never ended (the program hung writing history.png).
    TempDir dir;
    const std::vector<bbm::io::Series> zeros{{"ratio", {0.0}, {0.0}}};
    bbm::io::draw_curves(zeros, "step", "unbalanced-force ratio", dir.path / "empty_log.png", "convergence", true);
    CHECK(fs::file_size(dir.path / "empty_log.png") > 0);
    const std::vector<bbm::io::Series> none{{"nothing", {}, {}}};
    bbm::io::draw_curves(none, "step", "cracks", dir.path / "empty.png");
    CHECK(fs::file_size(dir.path / "empty.png") > 0);
}

TEST_CASE("the PNG writer writes what was drawn: a valid RGB file of the canvas's size, white paper and a curve") {
    // bbm writes PNGs with libpng at a fast zlib level rather than cairo's
    // writer; read back with libpng, the file must decode (CRCs, zlib stream)
    // to the picture: the paper white, the curve not.
    TempDir dir;
    const std::vector<bbm::io::Series> line{{"line", {0.0, 1.0, 2.0}, {0.0, 1.0, 4.0}}};
    const fs::path file = dir.path / "line.png";
    bbm::io::draw_curves(line, "x", "y", file);
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    REQUIRE(png_image_begin_read_from_file(&image, file.string().c_str()) != 0);
    CHECK((image.format & PNG_FORMAT_FLAG_COLOR) != 0);
    CHECK((image.format & PNG_FORMAT_FLAG_ALPHA) == 0);
    CHECK(image.width == 900);
    CHECK(image.height == 600);
    image.format = PNG_FORMAT_RGB;
    std::vector<unsigned char> pixels(PNG_IMAGE_SIZE(image));
    REQUIRE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr) != 0);
    auto rgb = [&](unsigned x, unsigned y) { return &pixels[3 * (std::size_t(y) * image.width + x)]; };
    for (const unsigned char* corner : {rgb(0, 0), rgb(image.width - 1, image.height - 1)})
        CHECK((corner[0] == 255 && corner[1] == 255 && corner[2] == 255));
    // The first series is drawn in dark blue (0.1, 0.2, 0.7): channels in order.
    std::size_t coloured = 0, blue = 0; // in a colour, not grey axes or black text
    for (std::size_t i = 0; i < pixels.size(); i += 3) {
        const unsigned char r = pixels[i], g = pixels[i + 1], b = pixels[i + 2];
        if (std::max({r, g, b}) - std::min({r, g, b}) <= 60) continue;
        ++coloured;
        blue += b > r + 60 && b > g + 60;
    }
    CHECK(coloured > 500);
    CHECK(blue > coloured * 9 / 10);
}
