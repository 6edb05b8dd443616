// voussoir/cgal.hpp: a CGAL::Surface_mesh (and a polygon soup) converted to a Voussoir mesh
// keeps its vertex order and positions bit for bit and gives the same solve as the arrays it
// came from; supports as a vertex range or a bool property map agree; results come back as
// property maps in the surface mesh's own vertex and edge handles; bad input is an Error.
#include "support.hpp"

#include <voussoir/cgal.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SM = CGAL::Surface_mesh<Point>;
using VI = SM::Vertex_index;

template <typename T>
bool same_bits(const std::vector<T> &a, const std::vector<T> &b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The surface mesh of `m`, vertices in order; `skip_first` adds and removes a vertex first,
// so that handles and Voussoir ids differ.
SM surface(const vsrt::MeshData &m, bool skip_first = false) {
    SM sm;
    VI removed;
    if (skip_first) removed = sm.add_vertex(Point(9, 9, 9));
    std::vector<VI> v;
    for (std::size_t i = 0; i < m.n_vertices(); ++i)
        v.push_back(sm.add_vertex(
            Point(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2])));
    for (std::size_t t = 0; t < m.n_faces(); ++t) {
        const auto f = sm.add_face(v[m.triangles[3 * t]], v[m.triangles[3 * t + 1]],
                                   v[m.triangles[3 * t + 2]]);
        EXPECT_NE(f, SM::null_face()) << "face " << t;
    }
    if (skip_first) sm.remove_vertex(removed);
    return sm;
}

std::vector<VI> handles(const SM &sm, const std::vector<uint32_t> &ids) {
    const std::vector<VI> all(sm.vertices().begin(), sm.vertices().end());
    std::vector<VI> out;
    for (uint32_t id : ids) out.push_back(all[id]);
    return out;
}

std::vector<double> points(const SM &sm) {
    std::vector<double> out;
    for (VI v : sm.vertices())
        for (int c = 0; c < 3; ++c) out.push_back(sm.point(v)[c]);
    return out;
}

class CgalRoundTrip : public ::testing::TestWithParam<bool> {};

TEST_P(CgalRoundTrip, RoundTripKeepsVertexOrderPositionsAndSolve) {
    const vsrt::MeshData m = vsrt::generated("disk_cap");
    SM sm = surface(m, GetParam());
    const voussoir::Mesh mesh = voussoir::cgal::to_mesh(sm, handles(sm, m.anchored));
    // An analysis reports the input positions and the mesh's edges: both as given.
    const voussoir::Result analysis = voussoir::analyse(mesh);
    EXPECT_TRUE(same_bits(analysis.positions(), m.positions));
    std::vector<uint32_t> edges;
    for (const auto &e : vsrt::sorted_edges(m)) edges.insert(edges.end(), e.begin(), e.end());
    EXPECT_EQ(analysis.edges(), edges);
    voussoir::cgal::set_positions(analysis, sm);
    EXPECT_TRUE(same_bits(points(sm), m.positions));
    // The same solve as from the arrays.
    const voussoir::Result found = voussoir::form_find(mesh);
    const voussoir::Result direct = voussoir::form_find(vsrt::make_mesh(m));
    EXPECT_TRUE(same_bits(found.positions(), direct.positions()));
    EXPECT_TRUE(same_bits(found.force_densities(), direct.force_densities()));
}

INSTANTIATE_TEST_SUITE_P(Cgal, CgalRoundTrip, ::testing::Values(false, true), [](const auto &info) {
    return info.param ? "with_removed_vertex" : "dense";
});

TEST(CgalAdapter, ResultsComeBackAsPropertyMaps) {
    const vsrt::MeshData m = vsrt::generated("disk_off_centre_hole");
    SM sm = surface(m, true);
    const voussoir::Result r =
        voussoir::form_find(voussoir::cgal::to_mesh(sm, handles(sm, m.anchored)));
    const std::vector<double> p = r.positions(), res = r.residuals(), q = r.force_densities();
    const std::vector<uint32_t> e = r.edges();
    const std::vector<VI> v(sm.vertices().begin(), sm.vertices().end());

    const auto moved = voussoir::cgal::add_positions(r, sm);
    const auto residual = voussoir::cgal::add_residuals(r, sm);
    const auto density = voussoir::cgal::add_force_densities(r, sm);
    for (std::size_t i = 0; i < v.size(); ++i) {
        EXPECT_EQ(moved[v[i]], Point(p[3 * i], p[3 * i + 1], p[3 * i + 2])) << "vertex " << i;
        EXPECT_EQ(residual[v[i]], res[i]) << "vertex " << i;
        EXPECT_TRUE(same_bits(std::vector<double>{sm.point(v[i]).z()}, {m.positions[3 * i + 2]}))
            << "add_positions moved the mesh";
    }
    ASSERT_EQ(q.size(), sm.number_of_edges());
    for (std::size_t k = 0; k < q.size(); ++k) {
        const auto h = sm.halfedge(v[e[2 * k]], v[e[2 * k + 1]]);
        ASSERT_NE(h, SM::null_halfedge());
        EXPECT_EQ(density[sm.edge(h)], q[k]) << "edge " << k;
    }
    voussoir::cgal::set_positions(r, sm);
    EXPECT_TRUE(same_bits(points(sm), p));
}

TEST(CgalAdapter, SupportsAsPropertyMapOrSoupGiveTheSameMesh) {
    const vsrt::MeshData m = vsrt::generated("disk_off_centre_hole");
    SM sm = surface(m);
    auto is_support = sm.add_property_map<VI, bool>("v:support", false).first;
    for (VI v : handles(sm, m.anchored)) is_support[v] = true;
    const std::vector<double> by_range =
        voussoir::analyse(voussoir::cgal::to_mesh(sm, handles(sm, m.anchored))).force_densities();
    const std::vector<double> by_map =
        voussoir::analyse(voussoir::cgal::to_mesh(sm, is_support)).force_densities();
    EXPECT_TRUE(same_bits(by_range, by_map));

    std::vector<Point> soup_points;
    for (std::size_t i = 0; i < m.n_vertices(); ++i)
        soup_points.emplace_back(m.positions[3 * i], m.positions[3 * i + 1],
                                 m.positions[3 * i + 2]);
    std::vector<std::vector<std::size_t>> polygons;
    for (std::size_t t = 0; t < m.n_faces(); ++t)
        polygons.push_back({m.triangles[3 * t], m.triangles[3 * t + 1], m.triangles[3 * t + 2]});
    const std::vector<std::size_t> supports(m.anchored.begin(), m.anchored.end());
    const std::vector<double> by_soup =
        voussoir::analyse(voussoir::cgal::to_mesh(soup_points, polygons, supports))
            .force_densities();
    EXPECT_TRUE(same_bits(by_range, by_soup));
}

void expect_error(const std::function<void()> &call, VsrStatus status, const std::string &message) {
    try {
        call();
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), status) << e.what();
        EXPECT_EQ(e.message(), message);
    }
}

TEST(CgalAdapter, BadInputIsAnError) {
    SM quad;
    const VI a = quad.add_vertex(Point(0, 0, 0)), b = quad.add_vertex(Point(1, 0, 0));
    const VI c = quad.add_vertex(Point(1, 1, 0)), d = quad.add_vertex(Point(0, 1, 0));
    quad.add_face(a, b, c, d);
    expect_error(
        [&] {
            (void)voussoir::cgal::to_mesh(quad, std::vector<VI>{a, b});
        },
        VSR_STATUS_INVALID_TOPOLOGY, "face 0 has 4 vertices; Voussoir takes triangles only");
    const std::vector<Point> pts = {Point(0, 0, 0), Point(1, 0, 0), Point(1, 1, 0), Point(0, 1, 0)};
    const std::vector<std::vector<std::size_t>> polys = {{0, 1, 2}, {0, 1, 2, 3}};
    expect_error([&] { (void)voussoir::cgal::to_mesh(pts, polys, {0}); },
                 VSR_STATUS_INVALID_TOPOLOGY,
                 "polygon 1 has 4 vertices; Voussoir takes triangles only");

    const vsrt::MeshData m = vsrt::generated("disk_cap");
    SM sm = surface(m);
    expect_error([&] { (void)voussoir::cgal::to_mesh(sm, std::vector<VI>{VI(100000)}); },
                 VSR_STATUS_INDEX_OUT_OF_RANGE,
                 "support 100000 is not a vertex of the surface mesh");
    // A result of another mesh does not fit.
    const voussoir::Result other =
        voussoir::analyse(voussoir::Mesh({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.3},
                                         {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4}, {0, 1, 2, 3}));
    expect_error(
        [&] { voussoir::cgal::set_positions(other, sm); }, VSR_STATUS_INVALID_ARGUMENT,
        "`result` has 5 vertices, the surface mesh " + std::to_string(sm.number_of_vertices()));
    // Library errors come through unchanged.
    try {
        (void)voussoir::cgal::to_mesh(sm, std::vector<VI>{});
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_NO_SUPPORT);
        EXPECT_NE(e.message().find("`anchored`"), std::string::npos) << e.message();
    }
}

}  // namespace
