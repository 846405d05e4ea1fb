// Reading density grids (src/scene/vdb_grid.h): a written grid reads back
// exactly, and every kind of bad .vdb input is an ub::InputError that names the
// file and the grid and says what is wrong. The bad files are created here
// (OpenVDB is included for the grid types the library refuses to write).
#include "scene/vdb_grid.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/rng.h"

namespace ub {
namespace {

namespace fs = std::filesystem;

class TempDir {
  public:
    TempDir() {
        path_ = fs::temp_directory_path() /
                ("unibeam_vdb_test_" + std::to_string(::getpid()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

  private:
    fs::path path_;
};

// Runs f, expects an InputError, returns its message.
template <typename F>
std::string inputErrorOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no ub::InputError thrown";
    return "";
}

void writeGrids(const std::string& path, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    openvdb::io::File(path).write(grids);
}

TEST(VdbGrid, WrittenGridReadsBackExactly) {
    TempDir tmp;
    DenseFloatGrid dense(11, 7, 5);
    dense.voxelSize = 0.05f;
    dense.origin = Vec3(1.0f, -2.0f, 0.5f);
    Rng rng(4, 0);
    for (float& v : dense.values) v = rng.uniform() < 0.2f ? 0.0f : 5.0f * rng.uniform();
    const std::string path = tmp.file("grid.vdb");
    writeDenseFloatVdb(path, "density", dense);
    auto grid = VdbGrid::load(path, "density");
    EXPECT_EQ(grid->name(), "density");
    auto acc = grid->grid().getAccessor();
    for (int k = 0; k < dense.nz; ++k)
        for (int j = 0; j < dense.ny; ++j)
            for (int i = 0; i < dense.nx; ++i) {
                ASSERT_EQ(acc.getValue(nanovdb::Coord(i, j, k)), dense.at(i, j, k));
                Vec3 p = grid->indexToLocal().point(Vec3(float(i), float(j), float(k)));
                Vec3 q = dense.origin + Vec3(float(i), float(j), float(k)) * dense.voxelSize;
                ASSERT_NEAR(length(p - q), 0.0f, 1e-5f);
            }
    EXPECT_GT(grid->byteSize(), 0u);
    EXPECT_NEAR(grid->maxValue(), *std::max_element(dense.values.begin(), dense.values.end()),
                0.0f);
}

TEST(VdbGrid, MissingFileIsInputError) {
    TempDir tmp;
    const std::string path = tmp.file("nope.vdb");
    std::string msg = inputErrorOf([&] { VdbGrid::load(path, "density"); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("'density'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("file not found"), std::string::npos) << msg;
}

TEST(VdbGrid, CorruptFileIsInputError) {
    TempDir tmp;
    const std::string path = tmp.file("text.vdb");
    std::ofstream(path) << "this is not a VDB file\n";
    std::string msg = inputErrorOf([&] { VdbGrid::load(path, "density"); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("'density'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not a readable OpenVDB file"), std::string::npos) << msg;
}

TEST(VdbGrid, UnknownGridNameListsGridsPresent) {
    TempDir tmp;
    const std::string path = tmp.file("two.vdb");
    auto smoke = openvdb::FloatGrid::create(0.0f);
    smoke->setName("smoke");
    smoke->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("vel");
    vel->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 0, 0));
    writeGrids(path, {smoke, vel});
    std::string msg = inputErrorOf([&] { VdbGrid::load(path, "density"); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("no grid of that name"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'smoke' (float)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'vel' (vec3s)"), std::string::npos) << msg;
}

TEST(VdbGrid, Vec3GridIsRejectedWithItsType) {
    TempDir tmp;
    const std::string path = tmp.file("vec3.vdb");
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("density");
    vel->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 0, 0));
    writeGrids(path, {vel});
    std::string msg = inputErrorOf([&] { VdbGrid::load(path, "density"); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("'density'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("type 'vec3s'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected a float"), std::string::npos) << msg;
}

TEST(VdbGrid, NegativeDensityIsRejected) {
    TempDir tmp;
    const std::string path = tmp.file("negative.vdb");
    DenseFloatGrid dense(4, 4, 4, 0.5f);
    dense.at(1, 2, 3) = -0.25f;
    writeDenseFloatVdb(path, "density", dense);
    std::string msg = inputErrorOf([&] { VdbGrid::load(path, "density"); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("grid 'density' has a negative density -0.25 at voxel (1, 2, 3)"),
              std::string::npos)
        << msg;
    // The same check applies to grids built in memory.
    msg = inputErrorOf([&] { VdbGrid::fromDense(dense, "density", "procedural"); });
    EXPECT_NE(msg.find("procedural"), std::string::npos) << msg;
    EXPECT_NE(msg.find("negative density -0.25"), std::string::npos) << msg;
}

TEST(VdbGrid, EmptyGridIsRejected) {
    TempDir tmp;
    const std::string path = tmp.file("empty.vdb");
    auto empty = openvdb::FloatGrid::create(0.0f);
    empty->setName("density");
    writeGrids(path, {empty});
    std::string msg = inputErrorOf([&] { VdbGrid::load(path, "density"); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("grid 'density' is empty"), std::string::npos) << msg;
}

// The committed media/smoke.vdb loads. When UNIBEAM_SMOKE_VDB names a freshly generated
// file (CTest test make_smoke_vdb.loads), that file loads too and equals the committed one
// voxel by voxel, so the committed grid can be regenerated with tools/make_smoke_vdb.
TEST(VdbGrid, SmokeFileLoads) {
    const std::string committed = std::string(UNIBEAM_SOURCE_DIR) + "/media/smoke.vdb";
    auto ref = VdbGrid::load(committed, "density");
    EXPECT_GT(ref->activeVoxelCount(), 1000u);
    EXPECT_LE(ref->maxValue(), 1.0f);
    const nanovdb::CoordBBox& bb = ref->indexBounds();
    for (int a = 0; a < 3; ++a) {
        EXPECT_GE(bb.min()[a], 0);
        EXPECT_LT(bb.max()[a], 64);
    }
    const char* generated = std::getenv("UNIBEAM_SMOKE_VDB");
    if (!generated) return;
    auto gen = VdbGrid::load(generated, "density");
    ASSERT_EQ(gen->activeVoxelCount(), ref->activeVoxelCount());
    auto a = ref->grid().getAccessor();
    auto b = gen->grid().getAccessor();
    for (int k = 0; k < 64; ++k)
        for (int j = 0; j < 64; ++j)
            for (int i = 0; i < 64; ++i)
                ASSERT_EQ(a.getValue(nanovdb::Coord(i, j, k)), b.getValue(nanovdb::Coord(i, j, k)))
                    << i << " " << j << " " << k;
}

}  // namespace
}  // namespace ub
