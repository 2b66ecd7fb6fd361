// Circumferences by horizontal plane slicing of a triangle mesh.
#include "caliper/circumference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "caliper/errors.hpp"

namespace caliper {

namespace {

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// The segments at each cut edge's point, in the order they were made: two on a manifold mesh,
// kept inline (a vector allocated per cut edge was a tenth of caliper batch --circumferences);
// more only where the mesh is not manifold.
struct Incident {
  int two[2] = {-1, -1};
  std::vector<int> more;
  std::size_t size() const {
    return static_cast<std::size_t>(two[0] >= 0) + static_cast<std::size_t>(two[1] >= 0) +
           more.size();
  }
  int at(std::size_t i) const { return i < 2 ? two[i] : more[i - 2]; }
  void push_back(int s) {
    if (two[0] < 0) {
      two[0] = s;
    } else if (two[1] < 0) {
      two[1] = s;
    } else {
      more.push_back(s);
    }
  }
};

// Where a horizontal plane cuts a mesh: a point (x, z) per cut edge, a segment per cut face
// between its two cut edges, and the segments at each point.
struct PlaneCut {
  std::unordered_map<std::uint64_t, Eigen::Vector2d> points;
  std::unordered_map<std::uint64_t, Incident> incident;  // key -> segment ids
  std::vector<std::pair<std::uint64_t, std::uint64_t>> segments;
};

PlaneCut cut_mesh(const smpl::Vertices& v, const smpl::Faces& faces, double height) {
  const auto nv = v.rows();
  // Which side of the plane each vertex is on (on-plane counts as above), computed once: the face
  // loop below then reads one byte per corner instead of a vertex row.
  std::vector<char> side(static_cast<std::size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) side[static_cast<std::size_t>(i)] = v(i, 1) - height >= 0.0;
  const auto above = [&](int i) { return side[static_cast<std::size_t>(i)]; };
  PlaneCut c;
  auto& points = c.points;
  auto& incident = c.incident;
  auto& segments = c.segments;
  // A level cuts a few hundred edges of a body: no rehashing while they are added.
  points.reserve(1024);
  incident.reserve(1024);
  segments.reserve(1024);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    int idx[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
    for (int k = 0; k < 3; ++k) {
      if (idx[k] < 0 || idx[k] >= nv) {
        throw InvalidInputError("slice_mesh: face " + std::to_string(f) +
                                " has a vertex index out of range");
      }
    }
    if (above(idx[0]) == above(idx[1]) && above(idx[1]) == above(idx[2])) continue;  // not cut
    std::uint64_t keys[2];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const int a = idx[k], b = idx[(k + 1) % 3];
      if (above(a) == above(b)) continue;
      const std::uint64_t key = edge_key(a, b);
      if (points.find(key) == points.end()) {
        // Interpolate from the lower-index vertex so both faces get the identical point.
        const int lo = std::min(a, b), hi = std::max(a, b);
        const double ya = v(lo, 1) - height, yb = v(hi, 1) - height;
        const double t = ya / (ya - yb);
        points[key] = Eigen::Vector2d(v(lo, 0) + t * (v(hi, 0) - v(lo, 0)),
                                      v(lo, 2) + t * (v(hi, 2) - v(lo, 2)));
      }
      if (n < 2) keys[n] = key;
      ++n;
    }
    if (n != 2) continue;
    const int s = static_cast<int>(segments.size());
    segments.emplace_back(keys[0], keys[1]);
    incident[keys[0]].push_back(s);
    incident[keys[1]].push_back(s);
  }
  return c;
}

// Chains the segments into loops: open chains from their ends (degree-1 points) first, then
// the closed loops; each with its length and centroid.
std::vector<SliceLoop> chain_segments(PlaneCut& c) {
  auto& points = c.points;
  auto& incident = c.incident;
  const auto& segments = c.segments;
  std::vector<char> used(segments.size(), 0);
  std::vector<SliceLoop> loops;
  const auto other_end = [&](int s, std::uint64_t key) {
    return segments[s].first == key ? segments[s].second : segments[s].first;
  };
  const auto next_segment = [&](std::uint64_t key) {
    const Incident& segs = incident[key];
    for (std::size_t i = 0; i < segs.size(); ++i) {
      if (!used[segs.at(i)]) return segs.at(i);
    }
    return -1;
  };
  // Start open chains at their ends (degree-1 points) first, then the closed loops.
  std::vector<std::uint64_t> starts;
  for (const auto& [key, segs] : incident) {
    if (segs.size() == 1) starts.push_back(key);
  }
  std::sort(starts.begin(), starts.end());
  for (std::size_t s0 = 0; s0 < segments.size(); ++s0) starts.push_back(segments[s0].first);
  for (std::uint64_t start : starts) {
    int s = next_segment(start);
    if (s < 0) continue;
    SliceLoop loop;
    std::uint64_t key = start;
    loop.points.push_back(points[key]);
    while (s >= 0) {
      used[s] = 1;
      key = other_end(s, key);
      if (key == start) {
        loop.closed = true;
        break;
      }
      loop.points.push_back(points[key]);
      s = next_segment(key);
    }
    const std::size_t m = loop.points.size();
    for (std::size_t i = 0; i + 1 < m; ++i)
      loop.length += (loop.points[i + 1] - loop.points[i]).norm();
    if (loop.closed && m > 1) loop.length += (loop.points.front() - loop.points.back()).norm();
    for (const auto& p : loop.points) loop.centroid += p;
    loop.centroid /= static_cast<double>(m);
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace

std::vector<SliceLoop> slice_mesh(const smpl::Vertices& v, const smpl::Faces& faces,
                                  double height) {
  PlaneCut cut = cut_mesh(v, faces, height);
  return chain_segments(cut);
}

double convex_hull_perimeter(const std::vector<Eigen::Vector2d>& input) {
  if (input.size() < 2) return 0.0;
  std::vector<Eigen::Vector2d> p = input;
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  std::vector<Eigen::Vector2d> hull(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {  // upper hull
    while (k >= t && cross2(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k);  // last point equals the first
  double per = 0.0;
  for (std::size_t i = 0; i + 1 < hull.size(); ++i) per += (hull[i + 1] - hull[i]).norm();
  return per;
}

bool loop_contains(const SliceLoop& loop, const Eigen::Vector2d& p) {
  bool inside = false;
  const auto& q = loop.points;
  for (std::size_t i = 0, j = q.size() - 1; i < q.size(); j = i++) {
    if ((q[i].y() > p.y()) != (q[j].y() > p.y()) &&
        p.x() < (q[j].x() - q[i].x()) * (p.y() - q[i].y()) / (q[j].y() - q[i].y()) + q[i].x()) {
      inside = !inside;
    }
  }
  return inside;
}

std::optional<double> circumference_between(const smpl::Vertices& vertices,
                                            const smpl::Faces& faces, double height, double x_min,
                                            double x_max, bool convex_hull) {
  const auto loops = slice_mesh(vertices, faces, height);
  std::vector<Eigen::Vector2d> pts;
  double length = 0.0;
  bool any = false;
  for (const auto& l : loops) {
    if (l.centroid.x() < x_min || l.centroid.x() > x_max) continue;
    any = true;
    length += l.length;
    pts.insert(pts.end(), l.points.begin(), l.points.end());
  }
  if (!any) return std::nullopt;
  return convex_hull ? convex_hull_perimeter(pts) : length;
}

const std::vector<std::string>& circumference_ids() {
  static const std::vector<std::string> ids = {"chest_circumference", "waist_circumference",
                                               "hip_circumference", "thigh_circumference"};
  return ids;
}

MeasurementMap circumferences(const smpl::Vertices& vertices, const smpl::Faces& faces,
                              const LandmarkTable& landmarks, bool convex_hull, double thigh_drop) {
  MeasurementMap out;
  const auto has = [&](const char* n) { return landmarks.count(n) > 0; };
  const auto pt = [&](const char* n) { return landmark_point(vertices, landmarks.at(n)); };
  const auto torso = [&](const char* id, double y, const char* left, const char* right) {
    if (!has(left) || !has(right)) return;
    const double xl = pt(left).x(), xr = pt(right).x();
    const auto c =
        circumference_between(vertices, faces, y, std::min(xl, xr), std::max(xl, xr), convex_hull);
    if (c) out[id] = *c;
  };
  if (has("left_nipple"))
    torso("chest_circumference", pt("left_nipple").y(), "left_chest", "right_chest");
  if (has("navel")) torso("waist_circumference", pt("navel").y(), "left_waist", "right_waist");
  if (has("left_hip")) torso("hip_circumference", pt("left_hip").y(), "left_hip", "right_hip");
  if (has("left_iliac_crest")) {
    torso("waist_iliac_circumference", pt("left_iliac_crest").y(), "left_iliac_crest",
          "right_iliac_crest");
  }
  if (has("crotch")) {
    const Eigen::Vector3d crotch = pt("crotch");
    const auto loops = slice_mesh(vertices, faces, crotch.y() - thigh_drop);
    const SliceLoop* best = nullptr;
    for (const auto& l : loops) {
      if (l.centroid.x() <= crotch.x()) continue;
      if (!best || l.centroid.x() < best->centroid.x()) best = &l;
    }
    if (best)
      out["thigh_circumference"] = convex_hull ? convex_hull_perimeter(best->points) : best->length;
  }
  return out;
}

}  // namespace caliper
