// Meshes formfind writes, read back by CGAL: the form-found shape as OFF (its equilibrium
// recomputed here from the force densities of formfind's report) and the printable solid of `--solid` and of
// vsr_result_write_solid_from_density (closed, free of self-intersections, bounding a volume
// of area x thickness), also at 97% of the largest thickness formfind accepts.
// .ci/cpp-tests.sh runs formfind on shared models into VSR_FORMFIND_DIR and lists
// `model thickness` per line in its manifest.txt (edge/manifest.txt for the thickest).
#include "support.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/boost/graph/helpers.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

constexpr double kTolerance = 1e-6;   // formfind's default tolerance on eps_inf

std::string formfind_dir() { return VSR_FORMFIND_DIR; }

// (model, thickness) per line of the manifest in `dir`; empty when there is none.
std::vector<std::pair<std::string, double>> manifest(const std::string &dir = formfind_dir()) {
    std::vector<std::pair<std::string, double>> out;
    std::ifstream in(dir + "/manifest.txt");
    std::string name;
    double thickness = 0;
    while (in >> name >> thickness) out.emplace_back(name, thickness);
    return out;
}

SurfaceMesh read_cgal(const std::string &path) {
    SurfaceMesh mesh;
    EXPECT_TRUE(CGAL::IO::read_polygon_mesh(path, mesh)) << "CGAL cannot read " << path;
    return mesh;
}

class Formfind : public ::testing::Test {
  protected:
    void SetUp() override {
        if (manifest().empty()) {
            if (vsrt::models_required())
                FAIL() << formfind_dir() << "/manifest.txt not found: .ci/cpp-tests.sh writes "
                       << "it with formfind, and CI requires it";
            GTEST_SKIP() << "skipped: no " << formfind_dir() << "/manifest.txt";
        }
    }
};

// The numbers of the array that follows `"key": ` in formfind's report (nested arrays
// flattened); formfind writes one top-level key per line.
std::vector<double> report_numbers(const std::string &report, const std::string &key) {
    const std::string tag = "\"" + key + "\": [";
    const std::size_t start = report.find(tag);
    if (start == std::string::npos) throw std::runtime_error("report has no " + key);
    std::vector<double> out;
    std::size_t i = start + tag.size() - 1;
    int depth = 0;
    do {
        const char c = report[i];
        if (c == '[') ++depth;
        else if (c == ']') --depth;
        else if (c == '-' || (c >= '0' && c <= '9')) {
            char *end = nullptr;
            out.push_back(std::strtod(report.c_str() + i, &end));
            i = static_cast<std::size_t>(end - report.c_str()) - 1;
        }
        ++i;
    } while (depth > 0 && i < report.size());
    return out;
}

std::string read_text(const std::string &path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Vertical and horizontal equilibrium of the shape CGAL read, recomputed here with CGAL's
// kernel from the force densities in formfind's report: r_i = sum_j q_ij (z_i - z_j) - p_i
// with p_i a third of the 3-D area of each face around i (density 1), over non-anchored
// vertices; at interior vertices sum_j q_ij (x_i - x_j, y_i - y_j) = 0.
TEST_F(Formfind, OffReadByCgalIsInEquilibrium) {
    for (const auto &[name, thickness] : manifest()) {
        const std::string path = formfind_dir() + "/" + name + ".off";
        const SurfaceMesh sm = read_cgal(path);
        const std::string report = read_text(formfind_dir() + "/" + name + ".json");
        const std::vector<double> edges = report_numbers(report, "edges");
        const std::vector<double> q = report_numbers(report, "force_densities");
        const std::vector<double> anchored_ids = report_numbers(report, "anchored");
        const std::size_t nv = sm.number_of_vertices();
        ASSERT_EQ(edges.size(), 2 * q.size()) << name;
        ASSERT_EQ(q.size(), sm.number_of_edges()) << name;
        std::vector<char> anchored(nv, 0), boundary(nv, 0);
        for (double a : anchored_ids) anchored.at(static_cast<std::size_t>(a)) = 1;
        for (auto h : sm.halfedges())
            if (sm.is_border(h)) boundary[sm.target(h).idx()] = 1;
        const auto point = [&](std::size_t v) {
            return sm.point(SurfaceMesh::Vertex_index(static_cast<uint32_t>(v)));
        };
        std::vector<double> load(nv, 0.0), r(nv, 0.0), hx(nv, 0.0), hy(nv, 0.0), scale(nv, 0.0);
        for (auto f : sm.faces()) {
            const double third = std::sqrt(CGAL::to_double(CGAL::squared_area(
                                     sm.point(sm.target(sm.halfedge(f))),
                                     sm.point(sm.target(sm.next(sm.halfedge(f)))),
                                     sm.point(sm.source(sm.halfedge(f)))))) / 3.0;
            for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) load[v.idx()] += third;
        }
        for (std::size_t e = 0; e < q.size(); ++e) {
            const auto a = static_cast<std::size_t>(edges[2 * e]);
            const auto b = static_cast<std::size_t>(edges[2 * e + 1]);
            const Kernel::Vector_3 d = point(a) - point(b);
            r[a] += q[e] * d.z(), r[b] -= q[e] * d.z();
            hx[a] += q[e] * d.x(), hx[b] -= q[e] * d.x();
            hy[a] += q[e] * d.y(), hy[b] -= q[e] * d.y();
            const double f = std::abs(q[e]) * std::sqrt(CGAL::to_double(d.squared_length()));
            scale[a] += f, scale[b] += f;
        }
        double mean = 0, worst = 0, worst_h = 0;
        std::size_t free = 0;
        for (std::size_t v = 0; v < nv; ++v)
            if (!anchored[v]) mean += load[v], ++free;
        mean /= static_cast<double>(free);
        for (std::size_t v = 0; v < nv; ++v) {
            if (anchored[v]) continue;
            worst = std::max(worst, std::abs(r[v] - load[v]) / mean);
            if (!boundary[v])
                worst_h = std::max(worst_h, std::hypot(hx[v], hy[v]) / (scale[v] + mean));
        }
        std::printf("%s (CGAL read of formfind's OFF, %zu vertices): eps_inf %.3e, horizontal "
                    "%.3e\n", path.c_str(), nv, worst, worst_h);
        EXPECT_LT(worst, kTolerance) << path;
        EXPECT_LT(worst_h, 1e-9) << path;
    }
}

// The CGAL checks of a printable solid of `mid` thickened by `thickness`.
void check_solid(const std::string &path, const SurfaceMesh &mid, double thickness) {
    const SurfaceMesh solid = read_cgal(path);
    ASSERT_TRUE(CGAL::is_triangle_mesh(solid)) << path;
    ASSERT_TRUE(CGAL::is_closed(solid)) << path;
    ASSERT_FALSE(PMP::does_self_intersect(solid)) << path;
    ASSERT_TRUE(PMP::does_bound_a_volume(solid)) << path;
    EXPECT_TRUE(PMP::is_outward_oriented(solid)) << path;
    const double volume = CGAL::to_double(PMP::volume(solid));
    const double expected = CGAL::to_double(PMP::area(mid)) * thickness;
    std::printf("%s: %zu faces, volume %.6e, mid-surface area x thickness %.6e (ratio %.5f)\n",
                path.c_str(), static_cast<std::size_t>(solid.number_of_faces()), volume,
                expected, volume / expected);
    EXPECT_NEAR(volume / expected, 1.0, 0.01) << path;
}

TEST_F(Formfind, SolidIsClosedAndBoundsAreaTimesThickness) {
    for (const auto &[name, thickness] : manifest()) {
        const SurfaceMesh mid = read_cgal(formfind_dir() + "/" + name + ".off");
        check_solid(formfind_dir() + "/" + name + "-solid.off", mid, thickness);
    }
}

// At 97% of the largest thickness formfind names when asked for too much (edge/manifest.txt):
// the solid is still closed and free of self-intersections, so the refusal comes in time.
TEST_F(Formfind, ThickestAcceptedSolidDoesNotIntersectItself) {
    const std::string edge = formfind_dir() + "/edge";
    ASSERT_FALSE(manifest(edge).empty()) << edge << "/manifest.txt";
    for (const auto &[name, thickness] : manifest(edge)) {
        const std::string path = edge + "/" + name + "-solid.off";
        const SurfaceMesh solid = read_cgal(path);
        ASSERT_TRUE(CGAL::is_closed(solid)) << path;
        ASSERT_FALSE(PMP::does_self_intersect(solid)) << path;
        ASSERT_TRUE(PMP::does_bound_a_volume(solid)) << path;
        std::printf("%s: thickness %.6g, closed, bounds a volume, no self-intersection\n",
                    path.c_str(), thickness);
    }
}

// The same through the C API, with the thickness from the (default, unit) face density.
TEST_F(Formfind, CApiSolidFromDensityPassesTheSameChecks) {
    for (const auto &[name, thickness] : manifest()) {
        const std::string off = formfind_dir() + "/" + name + ".off";
        const std::string supports = vsrt::models_dir() + "/" + name + ".json";
        voussoir::ReadOptions options;
        options.supports_path = supports;
        options.repair_tolerance = 0.0;
        const voussoir::Mesh mesh = voussoir::Mesh::read(off, options);
        const voussoir::Result result = voussoir::analyse(mesh);
        const std::string out = std::string(VSR_OUTPUT_DIR) + "/" + name + "-capi-solid.off";
        result.write_solid_from_density(mesh, 1.0 / thickness, out);
        check_solid(out, read_cgal(off), thickness);
    }
}

}  // namespace
