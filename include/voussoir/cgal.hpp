/*
 * voussoir/cgal.hpp: CGAL meshes to and from Voussoir (optional; needs CGAL 5 and
 * voussoir.hpp).
 *
 *   CGAL::Surface_mesh<K::Point_3> sm;  CGAL::IO::read_OFF("vault.off", sm);
 *   voussoir::Mesh mesh = voussoir::cgal::to_mesh(sm, supports);  // vertex range or bool map
 *   voussoir::Result result = voussoir::form_find(mesh);
 *   voussoir::cgal::set_positions(result, sm);                    // the form-found shape
 *   auto q = voussoir::cgal::add_force_densities(result, sm);      // edge property map
 *
 * Vertex i of the Voussoir mesh is the i-th vertex of sm.vertices() (its index when the
 * mesh has no removed elements), so results map back in that order. Faces must be
 * triangles (CGAL::Polygon_mesh_processing::triangulate_faces makes them so). Supports are
 * a range of vertex indices or a vertex property map of bool (e.g.
 * sm.add_property_map<Vertex_index, bool>("v:support")). Polygon soups (points and
 * triangles of point ids, as CGAL::IO::read_polygon_soup gives them) convert likewise.
 */
#ifndef VOUSSOIR_CGAL_HPP
#define VOUSSOIR_CGAL_HPP

#include <voussoir.hpp>

#include <CGAL/Surface_mesh.h>

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace voussoir {
namespace cgal {

namespace detail {

template <typename Range, typename Handle, typename = void>
struct is_handle_range : std::false_type {};
template <typename Range, typename Handle>
struct is_handle_range<Range, Handle,
                       std::void_t<decltype(std::begin(std::declval<const Range &>()))>>
    : std::is_same<std::decay_t<decltype(*std::begin(std::declval<const Range &>()))>, Handle> {};

template <typename Point>
void push_point(std::vector<double> &positions, const Point &p) {
    positions.push_back(CGAL::to_double(p.x()));
    positions.push_back(CGAL::to_double(p.y()));
    positions.push_back(CGAL::to_double(p.z()));
}

inline std::uint32_t vertex_id(std::size_t id, const char *what) {
    if (id > std::numeric_limits<std::uint32_t>::max())
        throw Error(VSR_STATUS_LENGTH_OVERFLOW,
                    std::string(what) + " " + std::to_string(id) + " does not fit 32 bits");
    return static_cast<std::uint32_t>(id);
}

inline Error not_a_triangle(const char *what, std::size_t index, std::size_t corners) {
    return Error(VSR_STATUS_INVALID_TOPOLOGY, std::string(what) + " " + std::to_string(index) +
                                                  " has " + std::to_string(corners) +
                                                  " vertices; Voussoir takes triangles only");
}

// Dense ids of a Surface_mesh's vertices in sm.vertices() order, indexed by Vertex_index.
template <typename Point>
std::vector<std::uint32_t> dense_ids(const CGAL::Surface_mesh<Point> &sm) {
    std::vector<std::uint32_t> ids(sm.num_vertices(), std::numeric_limits<std::uint32_t>::max());
    std::size_t next = 0;
    for (auto v : sm.vertices()) ids[v] = vertex_id(next++, "vertex");
    return ids;
}

template <typename Point>
std::vector<typename CGAL::Surface_mesh<Point>::Vertex_index> vertices(
    const CGAL::Surface_mesh<Point> &sm) {
    return {sm.vertices().begin(), sm.vertices().end()};
}

template <typename Point>
void check_vertex_count(const Result &result, const CGAL::Surface_mesh<Point> &sm) {
    const std::size_t n = result.counts().vertices;
    if (n != sm.number_of_vertices())
        throw Error(VSR_STATUS_INVALID_ARGUMENT, "`result` has " + std::to_string(n) +
                                                     " vertices, the surface mesh " +
                                                     std::to_string(sm.number_of_vertices()));
}

}  // namespace detail

/// The Voussoir mesh of a triangulated CGAL::Surface_mesh; `supports` is a range of its
/// Vertex_index or a vertex property map of bool. Throws Error.
template <typename Point, typename Supports>
Mesh to_mesh(const CGAL::Surface_mesh<Point> &sm, const Supports &supports) {
    using SM = CGAL::Surface_mesh<Point>;
    const std::vector<std::uint32_t> ids = detail::dense_ids(sm);
    std::vector<double> positions;
    positions.reserve(3 * sm.number_of_vertices());
    for (auto v : sm.vertices()) detail::push_point(positions, sm.point(v));
    std::vector<std::uint32_t> triangles;
    triangles.reserve(3 * sm.number_of_faces());
    std::size_t face = 0;
    for (auto f : sm.faces()) {
        const std::size_t corners = sm.degree(f);
        if (corners != 3) throw detail::not_a_triangle("face", face, corners);
        for (auto v : sm.vertices_around_face(sm.halfedge(f))) triangles.push_back(ids[v]);
        ++face;
    }
    std::vector<std::uint32_t> anchored;
    if constexpr (detail::is_handle_range<Supports, typename SM::Vertex_index>::value) {
        for (auto v : supports) {
            if (std::size_t(v) >= sm.num_vertices() || sm.is_removed(v))
                throw Error(VSR_STATUS_INDEX_OUT_OF_RANGE,
                            "support " + std::to_string(std::size_t(v)) +
                                " is not a vertex of the surface mesh");
            anchored.push_back(ids[v]);
        }
    } else {
        for (auto v : sm.vertices())
            if (get(supports, v)) anchored.push_back(ids[v]);
    }
    return Mesh(positions, triangles, anchored);
}

/// The Voussoir mesh of a polygon soup: points and triangles of point ids (any range of
/// ranges of integers); `supports` are point ids. Throws Error.
template <typename Point, typename Polygons>
Mesh to_mesh(const std::vector<Point> &points, const Polygons &polygons,
             const std::vector<std::size_t> &supports) {
    std::vector<double> positions;
    positions.reserve(3 * points.size());
    for (const Point &p : points) detail::push_point(positions, p);
    std::vector<std::uint32_t> triangles;
    std::size_t index = 0;
    for (const auto &polygon : polygons) {
        const auto corners =
            static_cast<std::size_t>(std::distance(std::begin(polygon), std::end(polygon)));
        if (corners != 3) throw detail::not_a_triangle("polygon", index, corners);
        for (auto id : polygon)
            triangles.push_back(detail::vertex_id(static_cast<std::size_t>(id), "point"));
        ++index;
    }
    std::vector<std::uint32_t> anchored;
    for (std::size_t id : supports) anchored.push_back(detail::vertex_id(id, "support"));
    return Mesh(positions, triangles, anchored);
}

/// Moves sm's points to the result's positions (same vertex order). Throws Error.
template <typename Point>
void set_positions(const Result &result, CGAL::Surface_mesh<Point> &sm) {
    detail::check_vertex_count(result, sm);
    const std::vector<double> p = result.positions();
    std::size_t i = 0;
    for (auto v : sm.vertices()) {
        sm.point(v) = Point(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        ++i;
    }
}

/// The result's positions as a vertex property map `name` of sm (added, or reused when it
/// exists); sm's own points stay. Throws Error.
template <typename Point>
typename CGAL::Surface_mesh<Point>::template Property_map<
    typename CGAL::Surface_mesh<Point>::Vertex_index, Point>
add_positions(const Result &result, CGAL::Surface_mesh<Point> &sm,
              const std::string &name = "v:voussoir_position") {
    using SM = CGAL::Surface_mesh<Point>;
    detail::check_vertex_count(result, sm);
    const std::vector<double> p = result.positions();
    auto map = sm.template add_property_map<typename SM::Vertex_index, Point>(name).first;
    std::size_t i = 0;
    for (auto v : sm.vertices()) {
        map[v] = Point(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        ++i;
    }
    return map;
}

/// The vertical residual per vertex (vsr_result_residuals) as a vertex property map.
template <typename Point>
typename CGAL::Surface_mesh<Point>::template Property_map<
    typename CGAL::Surface_mesh<Point>::Vertex_index, double>
add_residuals(const Result &result, CGAL::Surface_mesh<Point> &sm,
              const std::string &name = "v:voussoir_residual") {
    using SM = CGAL::Surface_mesh<Point>;
    detail::check_vertex_count(result, sm);
    const std::vector<double> r = result.residuals();
    auto map = sm.template add_property_map<typename SM::Vertex_index, double>(name, 0.0).first;
    std::size_t i = 0;
    for (auto v : sm.vertices()) map[v] = r[i++];
    return map;
}

/// The force density per edge (vsr_result_force_densities) as an edge property map (0 on
/// edges the result does not list).
template <typename Point>
typename CGAL::Surface_mesh<Point>::template Property_map<
    typename CGAL::Surface_mesh<Point>::Edge_index, double>
add_force_densities(const Result &result, CGAL::Surface_mesh<Point> &sm,
                    const std::string &name = "e:voussoir_force_density") {
    using SM = CGAL::Surface_mesh<Point>;
    detail::check_vertex_count(result, sm);
    const std::vector<std::uint32_t> edges = result.edges();
    const std::vector<double> q = result.force_densities();
    const auto handles = detail::vertices(sm);
    auto map = sm.template add_property_map<typename SM::Edge_index, double>(name, 0.0).first;
    for (auto e : sm.edges()) map[e] = 0.0;
    for (std::size_t e = 0; e < q.size(); ++e) {
        const auto h = sm.halfedge(handles[edges[2 * e]], handles[edges[2 * e + 1]]);
        if (h == SM::null_halfedge())
            throw Error(
                VSR_STATUS_INVALID_ARGUMENT,
                "edge " + std::to_string(e) + " of `result` is not an edge of the surface mesh");
        map[sm.edge(h)] = q[e];
    }
    return map;
}

}  // namespace cgal
}  // namespace voussoir

#endif  // VOUSSOIR_CGAL_HPP
