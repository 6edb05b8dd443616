// voussoir/openmesh.hpp: an OpenMesh TriMesh converted to a Voussoir mesh keeps its vertex
// order and positions bit for bit and gives the same solve as the arrays it came from;
// supports as handles, a VPropHandleT<bool> or a property manager agree; results come back as
// properties on the mesh's own handles; bad input is an Error.
#include "support.hpp"

#include <voussoir/openmesh.hpp>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Utils/PropertyManager.hh>

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace {

using TriMesh = OpenMesh::TriMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;
using FloatMesh = OpenMesh::TriMesh_ArrayKernelT<>;
using VH = OpenMesh::VertexHandle;

template <typename T>
bool same_bits(const std::vector<T> &a, const std::vector<T> &b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The TriMesh of `m`; `skip_first` adds a vertex first and deletes it (without garbage
// collection), so that handles and Voussoir ids differ.
template <typename M>
M trimesh(const vsrt::MeshData &m, bool skip_first = false) {
    M om;
    om.request_vertex_status();
    om.request_edge_status();
    om.request_face_status();
    VH removed;
    if (skip_first) removed = om.add_vertex(typename M::Point(9, 9, 9));
    std::vector<VH> v;
    for (std::size_t i = 0; i < m.n_vertices(); ++i)
        v.push_back(om.add_vertex(
            typename M::Point(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2])));
    for (std::size_t t = 0; t < m.n_faces(); ++t) {
        const auto f = om.add_face(v[m.triangles[3 * t]], v[m.triangles[3 * t + 1]],
                                   v[m.triangles[3 * t + 2]]);
        EXPECT_TRUE(f.is_valid()) << "face " << t;
    }
    if (skip_first) om.delete_vertex(removed);
    return om;
}

template <typename M>
std::vector<VH> handles(const M &om, const std::vector<uint32_t> &ids) {
    std::vector<VH> all;
    for (auto v : om.vertices()) all.push_back(v);
    std::vector<VH> out;
    for (uint32_t id : ids) out.push_back(all[id]);
    return out;
}

std::vector<double> points(const TriMesh &om) {
    std::vector<double> out;
    for (auto v : om.vertices())
        for (int c = 0; c < 3; ++c) out.push_back(om.point(v)[c]);
    return out;
}

class OpenMeshRoundTrip : public ::testing::TestWithParam<bool> {};

TEST_P(OpenMeshRoundTrip, RoundTripKeepsVertexOrderPositionsAndSolve) {
    const vsrt::MeshData m = vsrt::generated("disk_cap");
    TriMesh om = trimesh<TriMesh>(m, GetParam());
    const voussoir::Mesh mesh = voussoir::openmesh::to_mesh(om, handles(om, m.anchored));
    const voussoir::Result analysis = voussoir::analyse(mesh);
    EXPECT_TRUE(same_bits(analysis.positions(), m.positions));
    std::vector<uint32_t> edges;
    for (const auto &e : vsrt::sorted_edges(m)) edges.insert(edges.end(), e.begin(), e.end());
    EXPECT_EQ(analysis.edges(), edges);
    voussoir::openmesh::set_positions(analysis, om);
    EXPECT_TRUE(same_bits(points(om), m.positions));
    const voussoir::Result found = voussoir::form_find(mesh);
    const voussoir::Result direct = voussoir::form_find(vsrt::make_mesh(m));
    EXPECT_TRUE(same_bits(found.positions(), direct.positions()));
    EXPECT_TRUE(same_bits(found.force_densities(), direct.force_densities()));
}

INSTANTIATE_TEST_SUITE_P(OpenMesh, OpenMeshRoundTrip, ::testing::Values(false, true),
                         [](const auto &info) {
                             return info.param ? "with_deleted_vertex" : "dense";
                         });

TEST(OpenMeshAdapter, ResultsComeBackAsProperties) {
    const vsrt::MeshData m = vsrt::generated("disk_off_centre_hole");
    TriMesh om = trimesh<TriMesh>(m, true);
    const voussoir::Result r =
        voussoir::form_find(voussoir::openmesh::to_mesh(om, handles(om, m.anchored)));
    const std::vector<double> p = r.positions(), res = r.residuals(), q = r.force_densities();
    const std::vector<uint32_t> e = r.edges();
    const std::vector<VH> v = handles(om, [&] {
        std::vector<uint32_t> all(m.n_vertices());
        for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
        return all;
    }());

    const auto moved = voussoir::openmesh::add_positions(r, om);
    const auto residual = voussoir::openmesh::add_residuals(r, om);
    const auto density = voussoir::openmesh::add_force_densities(r, om);
    for (std::size_t i = 0; i < v.size(); ++i) {
        EXPECT_EQ(om.property(moved, v[i]), TriMesh::Point(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
        EXPECT_EQ(om.property(residual, v[i]), res[i]);
        EXPECT_EQ(om.point(v[i])[2], m.positions[3 * i + 2]) << "add_positions moved the mesh";
    }
    for (std::size_t k = 0; k < q.size(); ++k) {
        const auto h = om.find_halfedge(v[e[2 * k]], v[e[2 * k + 1]]);
        ASSERT_TRUE(h.is_valid());
        EXPECT_EQ(om.property(density, om.edge_handle(h)), q[k]) << "edge " << k;
    }
    // Adding again reuses the named property.
    EXPECT_EQ(voussoir::openmesh::add_residuals(r, om), residual);
    voussoir::openmesh::set_positions(r, om);
    EXPECT_TRUE(same_bits(points(om), p));
}

TEST(OpenMeshAdapter, SupportsAsPropertiesAgreeWithHandles) {
    const vsrt::MeshData m = vsrt::generated("disk_off_centre_hole");
    TriMesh om = trimesh<TriMesh>(m);
    OpenMesh::VPropHandleT<bool> marked;
    om.add_property(marked, "support");
    for (auto v : om.vertices()) om.property(marked, v) = false;
    for (VH v : handles(om, m.anchored)) om.property(marked, v) = true;
    OpenMesh::VProp<bool> managed(false, om);
    for (VH v : handles(om, m.anchored)) managed[v] = true;

    const auto q = [](const voussoir::Mesh &mesh) {
        return voussoir::analyse(mesh).force_densities();
    };
    const std::vector<double> by_handles =
        q(voussoir::openmesh::to_mesh(om, handles(om, m.anchored)));
    EXPECT_TRUE(same_bits(by_handles, q(voussoir::openmesh::to_mesh(om, marked))));
    EXPECT_TRUE(same_bits(by_handles, q(voussoir::openmesh::to_mesh(om, managed))));
}

TEST(OpenMeshAdapter, FloatPointsConvert) {
    const vsrt::MeshData m = vsrt::generated("disk_cap");
    FloatMesh om = trimesh<FloatMesh>(m);
    const voussoir::Result r =
        voussoir::form_find(voussoir::openmesh::to_mesh(om, handles(om, m.anchored)));
    EXPECT_TRUE(r.termination().converged()) << r.termination_message();
    voussoir::openmesh::set_positions(r, om);
    const std::vector<double> p = r.positions();
    std::size_t i = 0;
    for (auto v : om.vertices()) {
        EXPECT_EQ(om.point(v)[2], static_cast<float>(p[3 * i + 2]));
        ++i;
    }
}

TEST(OpenMeshAdapter, BadInputIsAnError) {
    const vsrt::MeshData m = vsrt::generated("disk_cap");
    TriMesh om = trimesh<TriMesh>(m);
    try {
        (void)voussoir::openmesh::to_mesh(om, std::vector<VH>{VH(100000)});
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_INDEX_OUT_OF_RANGE);
        EXPECT_EQ(e.message(), "support 100000 is not a vertex of the mesh");
    }
    const voussoir::Result other =
        voussoir::analyse(voussoir::Mesh({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.3},
                                         {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4}, {0, 1, 2, 3}));
    try {
        voussoir::openmesh::set_positions(other, om);
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_INVALID_ARGUMENT);
        EXPECT_EQ(e.message(),
                  "`result` has 5 vertices, the OpenMesh mesh " + std::to_string(om.n_vertices()));
    }
    try {
        (void)voussoir::openmesh::to_mesh(om, std::vector<VH>{});
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_NO_SUPPORT);
        EXPECT_NE(e.message().find("`anchored`"), std::string::npos) << e.message();
    }
}

}  // namespace
