// Series frames to and from VTU files with point and cell data, and ParaView collections (.pvd).
#include <amc/mesh_io.h>
#include <amc/series.h>
#include <amc/simulation.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <unistd.h>

namespace amc {
namespace {

SeriesFrame one_heat_frame() {
    HeatRunOptions options;
    options.frames = 2;
    options.max_level = 7;
    options.target_elements = 600;
    options.initial_adaptations = 3;
    SeriesFrame out;
    run_heat_simulation(options, [&](const SimulationFrame& f) { out = {*f.hierarchy, f.time, f.fields}; });
    return out;
}

template <class T>
void shuffle_tuples(std::vector<T>& v, const std::vector<uint32_t>& perm, uint32_t components) {
    std::vector<T> out(v.size());
    for (size_t i = 0; i < perm.size(); ++i)
        for (uint32_t k = 0; k < components; ++k) out[size_t(perm[i]) * components + k] = v[i * components + k];
    v.swap(out);
}

TEST(SeriesVtu, FramesThroughVtuFilesInAnyOrderComeBackCanonical) {
    const SeriesFrame frame = one_heat_frame();
    VtuMesh vtu = vtu_from_frame(frame);
    EXPECT_EQ(vtu.point_data.size(), 1u);
    EXPECT_EQ(vtu.cell_data.size(), 4u);  // error_indicator, heat_flux, level (the frame's), green
    // Another program's numbering: vertices and cells shuffled, arrays alike.
    std::mt19937 rng(5);
    std::vector<uint32_t> vperm(vtu.mesh.positions.size()), fperm(vtu.mesh.triangles.size());
    std::iota(vperm.begin(), vperm.end(), 0);
    std::iota(fperm.begin(), fperm.end(), 0);
    std::shuffle(vperm.begin(), vperm.end(), rng);
    std::shuffle(fperm.begin(), fperm.end(), rng);
    shuffle_tuples(vtu.mesh.positions, vperm, 1);
    for (Triangle& t : vtu.mesh.triangles)
        for (uint32_t& v : t) v = vperm[v];
    shuffle_tuples(vtu.mesh.triangles, fperm, 1);
    for (DataArray& a : vtu.point_data) std::visit([&](auto& v) { shuffle_tuples(v, vperm, a.components); }, a.values);
    for (DataArray& a : vtu.cell_data) std::visit([&](auto& v) { shuffle_tuples(v, fperm, a.components); }, a.values);

    const std::string path = (std::filesystem::temp_directory_path() / ("amc_series_" + std::to_string(getpid()) + ".vtu")).string();
    write_vtu(path, vtu);
    const SeriesFrame back = frame_from_vtu(frame.hierarchy.base(), read_vtu(path), frame.time, path);
    std::filesystem::remove(path);
    EXPECT_TRUE(identical(back.hierarchy, frame.hierarchy));
    ASSERT_EQ(back.fields.size(), 5u);
    for (const Field& f : frame.fields) {
        const auto it = std::find_if(back.fields.begin(), back.fields.end(), [&](const Field& g) { return g.name == f.name; });
        ASSERT_NE(it, back.fields.end()) << f.name;
        EXPECT_TRUE(identical(*it, f)) << f.name;
    }
    // The mesh of a level keeps the point fields' first values and no cell fields.
    const VtuMesh coarse = vtu_from_frame(frame, 2);
    ASSERT_EQ(coarse.point_data.size(), 1u);
    EXPECT_EQ(coarse.point_data[0].size(), coarse.mesh.positions.size());
    for (const DataArray& a : coarse.cell_data) EXPECT_TRUE(a.name == "level" || a.name == "green");
}

TEST(SeriesVtu, PvdCollectionsRoundTripAndBadOnesAreRefused) {
    const std::string dir = (std::filesystem::temp_directory_path() / ("amc_pvd_" + std::to_string(getpid()))).string();
    std::filesystem::create_directories(dir);
    const std::vector<PvdEntry> entries = {{0.0, "a_0.vtu"}, {0.1, "sub/a&b_1.vtu"}, {1e-300, "c.vtu"}};
    write_pvd(dir + "/s.pvd", entries);
    const std::vector<PvdEntry> back = read_pvd(dir + "/s.pvd");
    ASSERT_EQ(back.size(), entries.size());
    for (size_t i = 0; i < entries.size(); ++i) {
        EXPECT_EQ(back[i].time, entries[i].time);
        EXPECT_EQ(back[i].file, entries[i].file);
    }
    std::ofstream(dir + "/bad.pvd") << "<VTKFile type=\"Collection\"><Collection>\n<DataSet timestep=\"x\" file=\"a.vtu\"/>";
    try {
        read_pvd(dir + "/bad.pvd");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.pvd:2"), std::string::npos) << e.what();
    }
    // As ParaView and meshio write them too: comments, single quotes, character references.
    std::ofstream(dir + "/other.pvd") << "<?xml version=\"1.0\"?>\n<!-- <DataSet file=\"ghost.vtu\"/> -->\n"
                                         "<VTKFile type='Collection' version='0.1'>\n<Collection>\n"
                                         "<DataSet timestep='2.5' part='0' file='a&#38;b.vtu'/>\n<DataSet file=\"c.vtu\"/>\n"
                                         "</Collection>\n</VTKFile>\n";
    const std::vector<PvdEntry> other = read_pvd(dir + "/other.pvd");
    ASSERT_EQ(other.size(), 2u);
    EXPECT_EQ(other[0].file, "a&b.vtu");
    EXPECT_EQ(other[0].time, 2.5);
    EXPECT_EQ(other[1].file, "c.vtu");
    EXPECT_EQ(other[1].time, 1.0);  // no timestep: the entry's index
    std::ofstream(dir + "/empty.pvd") << "<VTKFile type=\"Collection\"><Collection></Collection></VTKFile>";
    EXPECT_THROW(read_pvd(dir + "/empty.pvd"), Error);
    std::ofstream(dir + "/not.pvd") << "hello";
    EXPECT_THROW(read_pvd(dir + "/not.pvd"), Error);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace amc
