// Shape measures of a body at rest (shape.hpp): a port of animat.shape, step for step, so that
// both give the same counts and the same numbers to rounding.
#include "animat/shape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>

#include <fmt/format.h>

#include "animat/body.hpp"
#include "animat/errors.hpp"

namespace animat {

namespace {

struct P2 {
  double x, y;
};

P2 row(const Points& p, Eigen::Index i) { return {p(i, 0), p(i, 1)}; }
double norm(double x, double y) { return std::sqrt(x * x + y * y); }

double shoelace(const std::vector<P2>& v) {
  if (v.size() < 3) return 0.0;
  double forward = 0.0, backward = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const P2& next = v[(i + 1) % v.size()];
    forward += v[i].x * next.y;
    backward += next.x * v[i].y;
  }
  return 0.5 * (forward - backward);
}

/// Convex hull vertices, counter-clockwise (Andrew's monotone chain), of the distinct points.
std::vector<P2> hull(const Points& p) {
  std::vector<std::pair<double, double>> pts;
  for (Eigen::Index i = 0; i < p.rows(); ++i) pts.emplace_back(p(i, 0), p(i, 1));
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  std::vector<P2> out;
  if (pts.size() < 3) {
    for (const auto& [x, y] : pts) out.push_back({x, y});
    return out;
  }
  auto cross = [](const P2& o, const P2& a, const std::pair<double, double>& b) {
    return (a.x - o.x) * (b.second - o.y) - (a.y - o.y) * (b.first - o.x);
  };
  auto chain = [&](auto begin, auto end) {
    std::vector<P2> c;
    for (auto it = begin; it != end; ++it) {
      while (c.size() >= 2 && cross(c[c.size() - 2], c.back(), *it) <= 0) c.pop_back();
      c.push_back({it->first, it->second});
    }
    c.pop_back();
    return c;
  };
  out = chain(pts.begin(), pts.end());
  const std::vector<P2> upper = chain(pts.rbegin(), pts.rend());
  out.insert(out.end(), upper.begin(), upper.end());
  return out;
}

/// The outline's edges a -> b in spacings, edges of zero length dropped.
struct Outline {
  std::vector<P2> a, b;
};

/// Squared distance from q to the segment a -> b.
double segment_distance2(const P2& q, const P2& a, const P2& b) {
  const double abx = b.x - a.x, aby = b.y - a.y;
  double ll = abx * abx + aby * aby;
  if (!(ll > 0)) ll = 1.0;
  const double t = std::clamp(((q.x - a.x) * abx + (q.y - a.y) * aby) / ll, 0.0, 1.0);
  const double x = q.x - (a.x + t * abx), y = q.y - (a.y + t * aby);
  return x * x + y * y;
}

/// Even-odd rule: q inside the closed polygon (an edge walked twice cancels).
bool inside(const P2& q, const Outline& o) {
  int hits = 0;
  for (std::size_t e = 0; e < o.a.size(); ++e) {
    const P2 &a = o.a[e], &b = o.b[e];
    if ((a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y)) ++hits;
  }
  return hits % 2 == 1;
}

/// Whether q lies inside the polygon at depth >= ρ (up to rounding); `lo`/`hi` its vertices' box.
bool in_core_erosion(const P2& q, const Outline& o, double rho, const P2& lo, const P2& hi) {
  const double level = rho * (1 - 1e-9) - 1e-12;
  // A point inside at depth d has the open disc of radius d inside, and every inside point lies in
  // the vertices' box: a point outside that box shrunk by the depth, or nearer than the depth to a
  // vertex, is no point of the erosion (the same margins as animat.shape's).
  const double margin = level - 1e-9;
  if (!(q.x >= lo.x + margin && q.y >= lo.y + margin && q.x <= hi.x - margin &&
        q.y <= hi.y - margin))
    return false;
  double vertex = std::numeric_limits<double>::infinity();
  for (const P2& a : o.a) {
    const double dx = q.x - a.x, dy = q.y - a.y;
    vertex = std::min(vertex, dx * dx + dy * dy);
  }
  if (!(vertex >= margin * margin)) return false;
  double d2 = std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < o.a.size(); ++e)
    d2 = std::min(d2, segment_distance2(q, o.a[e], o.b[e]));
  return std::sqrt(d2) >= level && inside(q, o);
}

/// Each cell's distance from the core in spacings (u: positions in spacings); empty when there is
/// no core (animat.shape.cell_heights).
std::vector<double> heights_above_core(const std::vector<P2>& u, std::span<const int> loop,
                                       double rho) {
  if (u.size() < 3 || loop.size() < 3) return {};
  Outline o;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const P2 a = u[static_cast<std::size_t>(loop[k])];
    const P2 b = u[static_cast<std::size_t>(loop[(k + 1) % loop.size()])];
    if (a.x != b.x || a.y != b.y) {
      o.a.push_back(a);
      o.b.push_back(b);
    }
  }
  const std::size_t edges = o.a.size();
  if (edges < 3) return {};
  P2 lo = o.a[0], hi = o.a[0];
  for (const P2& a : o.a) {
    lo = {std::min(lo.x, a.x), std::min(lo.y, a.y)};
    hi = {std::max(hi.x, a.x), std::max(hi.y, a.y)};
  }
  // The pieces of {depth = ρ}: the edges' offset lines (points on them, unit directions) and the
  // vertices' circles.
  std::vector<P2> off(edges), dir(edges);
  for (std::size_t k = 0; k < edges; ++k) {
    const double dx = o.b[k].x - o.a[k].x, dy = o.b[k].y - o.a[k].y, len = norm(dx, dy);
    dir[k] = {dx / len, dy / len};
    off[k] = {o.a[k].x + rho * -dir[k].y, o.a[k].y + rho * dir[k].x};
  }
  std::vector<std::pair<double, double>> unique_vertices;
  for (const P2& a : o.a) unique_vertices.emplace_back(a.x, a.y);
  std::sort(unique_vertices.begin(), unique_vertices.end());
  unique_vertices.erase(std::unique(unique_vertices.begin(), unique_vertices.end()),
                        unique_vertices.end());
  std::vector<P2> v;
  for (const auto& [x, y] : unique_vertices) v.push_back({x, y});

  // The core's candidate points, each kept when it lies in the erosion: the pieces' pairwise
  // intersections (within the box), then each cell's own candidates (itself, its projections on the
  // offset lines, its radial projections on the circles).
  std::vector<P2> core;
  auto consider = [&](const P2& q) {
    if (in_core_erosion(q, o, rho, lo, hi)) core.push_back(q);
  };
  auto consider_corner = [&](const P2& q) {
    if (q.x >= lo.x - 1e-9 && q.y >= lo.y - 1e-9 && q.x <= hi.x + 1e-9 && q.y <= hi.y + 1e-9)
      consider(q);
  };
  for (std::size_t k = 0; k < edges; ++k)
    for (std::size_t l = k + 1; l < edges; ++l) {
      const double cross = dir[k].x * dir[l].y - dir[k].y * dir[l].x;
      if (!(std::abs(cross) > 1e-12)) continue;
      const double wx = off[l].x - off[k].x, wy = off[l].y - off[k].y;
      const double s = (wx * dir[l].y - wy * dir[l].x) / cross;
      consider_corner({off[k].x + s * dir[k].x, off[k].y + s * dir[k].y});
    }
  for (const double sign : {-1.0, 1.0})
    for (std::size_t k = 0; k < edges; ++k)
      for (const P2& c : v) {
        const double wx = off[k].x - c.x, wy = off[k].y - c.y;
        const double wt = wx * dir[k].x + wy * dir[k].y;
        const double disc = wt * wt - (wx * wx + wy * wy) + rho * rho;
        if (!(disc >= 0)) continue;
        const double t = -wt + sign * std::sqrt(disc);
        consider_corner({off[k].x + t * dir[k].x, off[k].y + t * dir[k].y});
      }
  for (const double sign : {1.0, -1.0})
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t j = i + 1; j < v.size(); ++j) {
        const double gx = v[j].x - v[i].x, gy = v[j].y - v[i].y, dist = norm(gx, gy);
        if (!(dist > 0 && dist <= 2 * rho)) continue;
        const double half = std::sqrt(std::max(0.0, rho * rho - dist * dist / 4));
        const double mx = (v[i].x + v[j].x) / 2, my = (v[i].y + v[j].y) / 2;
        consider_corner({mx + sign * half * (-gy / dist), my + sign * half * (gx / dist)});
      }
  for (const P2& q : u) {
    consider(q);
    for (std::size_t k = 0; k < edges; ++k) {
      const double along = (q.x - off[k].x) * dir[k].x + (q.y - off[k].y) * dir[k].y;
      consider({off[k].x + along * dir[k].x, off[k].y + along * dir[k].y});
    }
    for (const P2& c : v) {
      const double rx = q.x - c.x, ry = q.y - c.y, r = norm(rx, ry);
      if (r > 0) consider({c.x + rho * rx / r, c.y + rho * ry / r});
    }
  }
  if (core.empty()) return {};
  std::vector<double> heights;
  heights.reserve(u.size());
  for (const P2& q : u) {
    double d2 = std::numeric_limits<double>::infinity();
    for (const P2& c : core) {
      const double dx = q.x - c.x, dy = q.y - c.y;
      d2 = std::min(d2, dx * dx + dy * dy);
    }
    heights.push_back(std::max(0.0, std::sqrt(d2) - rho));
  }
  return heights;
}

}  // namespace

// By union-find keeping the least index as root, as animat.shape.connected_groups.
std::vector<std::vector<int>> connected_groups(const std::vector<int>& members,
                                               const std::vector<std::pair<int, int>>& links) {
  std::map<int, int> parent;
  for (int m : members) parent[m] = m;
  auto find = [&](int x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  for (const auto& [i, j] : links)
    if (parent.count(i) && parent.count(j)) {
      const int ri = find(i), rj = find(j);
      if (ri != rj) parent[std::max(ri, rj)] = std::min(ri, rj);
    }
  std::vector<std::vector<int>> groups;
  std::map<int, std::size_t> slot;
  for (int m : members) {
    const auto [it, fresh] = slot.try_emplace(find(m), groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(m);
  }
  for (auto& g : groups) std::sort(g.begin(), g.end());
  return groups;
}

std::vector<double> cell_heights(const Points& positions, std::span<const int> outline,
                                 const ShapeParams& params, double spacing) {
  std::vector<P2> u;
  u.reserve(static_cast<std::size_t>(positions.rows()));
  for (Eigen::Index i = 0; i < positions.rows(); ++i)
    u.push_back({positions(i, 0) / spacing, positions(i, 1) / spacing});
  return heights_above_core(u, outline, params.core_radius);
}

std::vector<std::pair<int, int>> symmetric_pairs(
    const Points& positions, const std::vector<std::array<double, 2>>& centroids,
    const ShapeParams& params, double spacing) {
  std::vector<std::pair<int, int>> pairs;
  const Eigen::Index n = positions.rows();
  if (n == 0) return pairs;
  const PrincipalAxes axes = principal_axes(positions, params.cell_diameter, spacing);
  const double mx = positions.col(0).sum() / static_cast<double>(n);
  const double my = positions.col(1).sum() / static_cast<double>(n);
  const double s = spacing;
  const std::size_t count = centroids.size();
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t j = i + 1; j < count; ++j) {
      const auto& pi = centroids[i];
      const auto& pj = centroids[j];
      const double ax = (pi[0] - mx) / s, ay = (pi[1] - my) / s;
      const double bx = (pj[0] - mx) / s, by = (pj[1] - my) / s;
      for (const double* normal : {axes.major_axis, axes.minor_axis}) {
        const double an = ax * normal[0] + ay * normal[1];
        const double bn = bx * normal[0] + by * normal[1];
        const double rx = ax - 2.0 * an * normal[0], ry = ay - 2.0 * an * normal[1];
        if (an * bn < 0 && norm(rx - bx, ry - by) <= params.pair_tolerance) {
          pairs.emplace_back(static_cast<int>(i), static_cast<int>(j));
          break;
        }
      }
    }
  return pairs;
}

PrincipalAxes principal_axes(const Points& positions, double cell_diameter, double spacing) {
  const Eigen::Index n = positions.rows();
  const double count = static_cast<double>(n);
  const double mx = positions.col(0).sum() / count, my = positions.col(1).sum() / count;
  double xx = 0.0, yy = 0.0, xy = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double x = positions(i, 0) - mx, y = positions(i, 1) - my;
    xx += x * x;
    yy += y * y;
    xy += x * y;
  }
  const double disc = (cell_diameter * spacing) * (cell_diameter * spacing) / 16.0;
  xx = xx / count + disc;
  yy = yy / count + disc;
  xy /= count;
  // The eigen-decomposition of the symmetric 2 × 2 matrix [[xx, xy], [xy, yy]].
  const double mid = 0.5 * (xx + yy), radius = std::hypot(0.5 * (xx - yy), xy);
  const double angle = 0.5 * std::atan2(2.0 * xy, xx - yy);
  PrincipalAxes axes;
  axes.major = mid + radius;
  axes.minor = mid - radius;
  axes.major_axis[0] = std::cos(angle);
  axes.major_axis[1] = std::sin(angle);
  axes.minor_axis[0] = -axes.major_axis[1];
  axes.minor_axis[1] = axes.major_axis[0];
  return axes;
}

double elongation(const Points& positions, double cell_diameter, double spacing) {
  if (positions.rows() == 0) return 1.0;
  const PrincipalAxes m = principal_axes(positions, cell_diameter, spacing);
  if (m.major <= 0.0) return 1.0;
  if (m.minor <= 1e-12 * m.major) return std::numeric_limits<double>::infinity();
  return std::sqrt(m.major / m.minor);
}

double elongation(const Points& positions, double cell_diameter) {
  return elongation(positions, cell_diameter, cell_spacing(positions));
}

Shape describe_shape(const Points& positions, std::span<const int> outline,
                     const IndexPairs* springs, const ShapeParams& params, double spacing) {
  const Eigen::Index n = positions.rows();
  for (int i : outline)
    if (i < 0 || i >= n)
      throw GeometryError(
          fmt::format("describe_shape: outline index {} is not a cell (0..{})", i, n - 1));
  Shape out;
  out.spacing = std::isnan(spacing) ? cell_spacing(positions) : spacing;
  const double s = out.spacing;
  if (n == 0) return out;
  out.cell_count = static_cast<int>(n);
  out.elongation = elongation(positions, params.cell_diameter, s);
  std::vector<P2> loop;
  for (int i : outline) loop.push_back(row(positions, i));
  const double a_out = outline.size() >= 3 ? std::abs(shoelace(loop)) : 0.0;
  const double a_hull = n >= 3 ? std::abs(shoelace(hull(positions))) : 0.0;
  out.concavity = a_hull < std::sqrt(3.0) / 4.0 * s * s
                      ? 0.0
                      : std::min(1.0, std::max(0.0, 1.0 - a_out / a_hull));
  out.outline_area = a_out / (s * s);
  out.hull_area = a_hull / (s * s);

  out.heights = cell_heights(positions, outline, params, s);
  if (out.heights.empty()) {
    out.heights.assign(static_cast<std::size_t>(n), 0.0);
    return out;
  }
  out.has_core = true;
  std::vector<int> protruding;
  for (int i = 0; i < n; ++i)
    if (out.heights[static_cast<std::size_t>(i)] >= params.min_height) protruding.push_back(i);
  out.core_cells = static_cast<int>(n) - static_cast<int>(protruding.size());
  std::vector<std::pair<int, int>> links;
  for (std::size_t k = 0; k < outline.size(); ++k)
    links.emplace_back(outline[k], outline[(k + 1) % outline.size()]);
  if (springs != nullptr) {
    for (Eigen::Index e = 0; e < springs->rows(); ++e)
      links.emplace_back((*springs)(e, 0), (*springs)(e, 1));
  } else {
    for (int i : protruding)
      for (int j : protruding) {
        const P2 a = row(positions, i), b = row(positions, j);
        if (i < j && norm(a.x - b.x, a.y - b.y) < 1.5 * s) links.emplace_back(i, j);
      }
  }
  for (std::vector<int>& g : connected_groups(protruding, links)) {
    Protrusion p;
    double cx = 0.0, cy = 0.0;
    for (int i : g) {
      p.height = std::max(p.height, out.heights[static_cast<std::size_t>(i)]);
      cx += positions(i, 0);
      cy += positions(i, 1);
    }
    p.centroid[0] = cx / static_cast<double>(g.size());
    p.centroid[1] = cy / static_cast<double>(g.size());
    p.cells = std::move(g);
    out.protrusions.push_back(std::move(p));
  }
  std::sort(
      out.protrusions.begin(), out.protrusions.end(), [](const Protrusion& a, const Protrusion& b) {
        const auto as = static_cast<long>(a.cells.size()), bs = static_cast<long>(b.cells.size());
        const double ah = -a.height, bh = -b.height;
        return std::tie(bs, ah, a.cells) < std::tie(as, bh, b.cells);
      });

  std::vector<std::array<double, 2>> centroids;
  for (const Protrusion& p : out.protrusions) centroids.push_back({p.centroid[0], p.centroid[1]});
  out.symmetric_pairs = symmetric_pairs(positions, centroids, params, s);
  return out;
}

Shape body_shape(const Body& body, const ShapeParams& params) {
  static const std::vector<int> none;
  const std::vector<int>& outline = body.skin_loops.empty() ? none : body.skin_loops[0];
  return describe_shape(body.positions, outline, &body.springs, params);
}

}  // namespace animat
