/*
 * voussoir/openmesh.hpp: OpenMesh triangle meshes to and from Voussoir (optional; needs
 * OpenMesh 8 or later and voussoir.hpp).
 *
 *   using TriMesh = OpenMesh::TriMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;
 *   TriMesh om;  OpenMesh::IO::read_mesh(om, "vault.obj");
 *   voussoir::Mesh mesh = voussoir::openmesh::to_mesh(om, supports);  // handles or bool property
 *   voussoir::Result result = voussoir::form_find(mesh);
 *   voussoir::openmesh::set_positions(result, om);                     // the form-found shape
 *   auto q = voussoir::openmesh::add_force_densities(result, om);       // EPropHandleT<double>
 *
 * Vertex i of the Voussoir mesh is the i-th vertex of om.vertices() (its idx() when nothing
 * is deleted), so results map back in that order. Supports are a range of vertex handles, an
 * OpenMesh::VPropHandleT<bool>, or a property manager indexed by vertex handle
 * (OpenMesh::VProp<bool>). Points of float traits convert; use double points
 * (DefaultTraitsDouble) to keep the form-found equilibrium, which single precision loses.
 */
#ifndef VOUSSOIR_OPENMESH_HPP
#define VOUSSOIR_OPENMESH_HPP

#include <voussoir.hpp>

#include <OpenMesh/Core/Mesh/Handles.hh>
#include <OpenMesh/Core/Utils/Property.hh>

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace voussoir {
namespace openmesh {

namespace detail {

template <typename Range, typename = void>
struct is_handle_range : std::false_type {};
template <typename Range>
struct is_handle_range<Range, std::void_t<decltype(std::begin(std::declval<const Range &>()))>>
    : std::is_base_of<OpenMesh::VertexHandle,
                      std::decay_t<decltype(*std::begin(std::declval<const Range &>()))>> {};

template <typename TriMesh>
std::vector<OpenMesh::VertexHandle> vertices(const TriMesh &om) {
    std::vector<OpenMesh::VertexHandle> out;
    for (auto v : om.vertices()) out.push_back(v);
    return out;
}

template <typename TriMesh>
std::vector<OpenMesh::VertexHandle> checked_vertices(const Result &result, const TriMesh &om) {
    std::vector<OpenMesh::VertexHandle> handles = vertices(om);
    const std::size_t n = result.counts().vertices;
    if (n != handles.size())
        throw Error(VSR_STATUS_INVALID_ARGUMENT, "`result` has " + std::to_string(n) +
                                                     " vertices, the OpenMesh mesh " +
                                                     std::to_string(handles.size()));
    return handles;
}

template <typename Handle, typename TriMesh>
Handle property(TriMesh &om, const std::string &name) {
    Handle handle;
    if (!om.get_property_handle(handle, name)) om.add_property(handle, name);
    return handle;
}

template <typename TriMesh>
typename TriMesh::Point point(const std::vector<double> &p, std::size_t i) {
    using Scalar = typename TriMesh::Point::value_type;
    return typename TriMesh::Point(static_cast<Scalar>(p[3 * i]), static_cast<Scalar>(p[3 * i + 1]),
                                   static_cast<Scalar>(p[3 * i + 2]));
}

}  // namespace detail

/// The Voussoir mesh of an OpenMesh triangle mesh; `supports` is a range of vertex handles,
/// a VPropHandleT<bool>, or a property manager of bool. Throws Error.
template <typename TriMesh, typename Supports>
Mesh to_mesh(const TriMesh &om, const Supports &supports) {
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> ids(om.n_vertices(), none);
    std::vector<double> positions;
    positions.reserve(3 * om.n_vertices());
    std::uint32_t next = 0;
    for (auto v : om.vertices()) {
        ids[static_cast<std::size_t>(v.idx())] = next++;
        for (int c = 0; c < 3; ++c) positions.push_back(static_cast<double>(om.point(v)[c]));
    }
    std::vector<std::uint32_t> triangles;
    triangles.reserve(3 * om.n_faces());
    std::size_t face = 0;
    for (auto f : om.faces()) {
        std::size_t corners = 0;
        for (auto v : om.fv_range(f)) {
            triangles.push_back(ids[static_cast<std::size_t>(v.idx())]);
            ++corners;
        }
        if (corners != 3)
            throw Error(VSR_STATUS_INVALID_TOPOLOGY,
                        "face " + std::to_string(face) + " has " + std::to_string(corners) +
                            " vertices; Voussoir takes triangles only");
        ++face;
    }
    std::vector<std::uint32_t> anchored;
    if constexpr (detail::is_handle_range<Supports>::value) {
        for (const OpenMesh::VertexHandle v : supports) {
            if (!v.is_valid() || static_cast<std::size_t>(v.idx()) >= ids.size() ||
                ids[static_cast<std::size_t>(v.idx())] == none)
                throw Error(VSR_STATUS_INDEX_OUT_OF_RANGE,
                            "support " + std::to_string(v.idx()) + " is not a vertex of the mesh");
            anchored.push_back(ids[static_cast<std::size_t>(v.idx())]);
        }
    } else if constexpr (std::is_same<Supports, OpenMesh::VPropHandleT<bool>>::value) {
        for (auto v : om.vertices())
            if (om.property(supports, v))
                anchored.push_back(ids[static_cast<std::size_t>(v.idx())]);
    } else {
        for (auto v : om.vertices())
            if (supports[v]) anchored.push_back(ids[static_cast<std::size_t>(v.idx())]);
    }
    return Mesh(positions, triangles, anchored);
}

/// Moves the mesh's points to the result's positions (same vertex order). Throws Error.
template <typename TriMesh>
void set_positions(const Result &result, TriMesh &om) {
    const auto handles = detail::checked_vertices(result, om);
    const std::vector<double> p = result.positions();
    for (std::size_t i = 0; i < handles.size(); ++i)
        om.set_point(handles[i], detail::point<TriMesh>(p, i));
}

/// The result's positions as a vertex property `name` (added, or reused when it exists);
/// the mesh's own points stay. Throws Error.
template <typename TriMesh>
OpenMesh::VPropHandleT<typename TriMesh::Point> add_positions(
    const Result &result, TriMesh &om, const std::string &name = "voussoir:position") {
    const auto handles = detail::checked_vertices(result, om);
    const std::vector<double> p = result.positions();
    auto prop = detail::property<OpenMesh::VPropHandleT<typename TriMesh::Point>>(om, name);
    for (std::size_t i = 0; i < handles.size(); ++i)
        om.property(prop, handles[i]) = detail::point<TriMesh>(p, i);
    return prop;
}

/// The vertical residual per vertex (vsr_result_residuals) as a vertex property.
template <typename TriMesh>
OpenMesh::VPropHandleT<double> add_residuals(const Result &result, TriMesh &om,
                                             const std::string &name = "voussoir:residual") {
    const auto handles = detail::checked_vertices(result, om);
    const std::vector<double> r = result.residuals();
    auto prop = detail::property<OpenMesh::VPropHandleT<double>>(om, name);
    for (std::size_t i = 0; i < handles.size(); ++i) om.property(prop, handles[i]) = r[i];
    return prop;
}

/// The force density per edge (vsr_result_force_densities) as an edge property (0 on edges
/// the result does not list). Throws Error.
template <typename TriMesh>
OpenMesh::EPropHandleT<double> add_force_densities(
    const Result &result, TriMesh &om, const std::string &name = "voussoir:force_density") {
    const auto handles = detail::checked_vertices(result, om);
    const std::vector<std::uint32_t> edges = result.edges();
    const std::vector<double> q = result.force_densities();
    auto prop = detail::property<OpenMesh::EPropHandleT<double>>(om, name);
    for (auto e : om.edges()) om.property(prop, e) = 0.0;
    for (std::size_t e = 0; e < q.size(); ++e) {
        const auto h = om.find_halfedge(handles[edges[2 * e]], handles[edges[2 * e + 1]]);
        if (!h.is_valid())
            throw Error(VSR_STATUS_INVALID_ARGUMENT,
                        "edge " + std::to_string(e) + " of `result` is not an edge of the mesh");
        om.property(prop, om.edge_handle(h)) = q[e];
    }
    return prop;
}

}  // namespace openmesh
}  // namespace voussoir

#endif  // VOUSSOIR_OPENMESH_HPP
