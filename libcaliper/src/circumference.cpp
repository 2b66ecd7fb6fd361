// Circumferences by horizontal plane slicing of a triangle mesh.
#include "caliper/circumference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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

// The faces each plane y = heights[i] cuts, in increasing order, into cut[i], checking the
// indices. A face is cut when one corner is below the plane and one is on or above it (a vertex
// on the plane counts as above: the 1e-12 m nudge; a NaN corner counts as below). One pass over
// the vertices marks, in a byte per vertex, which of (up to 8) planes each is on or above; one
// pass over the faces then reads three bytes per face (a 12 KB table for 12,000 vertices: in L1)
// for all planes at once instead of three vertex rows per plane (circumferences() slices a body
// five times).
void cut_faces(const smpl::Vertices& v, const smpl::Faces& faces,
               const std::vector<double>& heights, std::vector<std::vector<int>>& cut) {
  const Eigen::Index nv = v.rows();
  cut.assign(heights.size(), {});
  for (auto& c : cut) c.reserve(512);
  std::vector<std::uint8_t> above(static_cast<std::size_t>(nv));
  for (std::size_t h0 = 0; h0 < heights.size(); h0 += 8) {
    const std::size_t n = std::min<std::size_t>(8, heights.size() - h0);
    for (Eigen::Index i = 0; i < nv; ++i) {
      unsigned bits = 0;
      for (std::size_t h = 0; h < n; ++h)
        bits |= static_cast<unsigned>(v(i, 1) - heights[h0 + h] >= 0.0) << h;
      above[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits);
    }
    const std::int32_t* face = faces.data();
    const auto unv = static_cast<std::uint64_t>(nv);
    for (Eigen::Index f = 0; f < faces.rows(); ++f, face += 3) {
      // A negative index becomes a huge unsigned one: one comparison per face.
      const auto i0 = static_cast<std::uint32_t>(face[0]), i1 = static_cast<std::uint32_t>(face[1]),
                 i2 = static_cast<std::uint32_t>(face[2]);
      if (std::max(i0, std::max(i1, i2)) >= unv) {
        throw InvalidInputError("slice_mesh: face " + std::to_string(f) +
                                " has a vertex index out of range");
      }
      const unsigned a = above[i0], b = above[i1], c = above[i2];
      unsigned mixed = (a | b | c) & ~(a & b & c);  // planes with corners on both sides
      while (mixed) {
        const int h = __builtin_ctz(mixed);
        cut[h0 + static_cast<std::size_t>(h)].push_back(static_cast<int>(f));
        mixed &= mixed - 1;
      }
    }
  }
}

// Where a horizontal plane cuts a mesh: a point (x, z) per cut edge (numbered in the order of
// the edges' keys), a segment per cut face between its two cut edges' points, and the segments
// at each point.
struct PlaneCut {
  std::vector<Eigen::Vector2d> points;
  std::vector<Incident> incident;  // point -> segment ids
  std::vector<std::pair<int, int>> segments;
};

// The cut of the faces `cut` (in increasing order, each cut by the plane).
PlaneCut cut_mesh(const smpl::Vertices& v, const smpl::Faces& faces, double height,
                  const std::vector<int>& cut) {
  // Both cut edges of every cut face, keyed by their vertex pair, then numbered by sorting the
  // keys: a few hundred entries, no hash map.
  struct End {
    std::uint64_t key;
    int slot;  // 2 * segment + end
  };
  std::vector<End> ends;
  ends.reserve(2 * cut.size());
  for (std::size_t s = 0; s < cut.size(); ++s) {
    const int f = cut[s];
    const int idx[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
    int n = 0;
    for (int k = 0; k < 3 && n < 2; ++k) {
      const int a = idx[k], b = idx[(k + 1) % 3];
      if ((v(a, 1) - height >= 0.0) == (v(b, 1) - height >= 0.0)) continue;
      ends.push_back({edge_key(a, b), static_cast<int>(2 * s) + n});
      ++n;
    }
  }
  std::sort(ends.begin(), ends.end(), [](const End& a, const End& b) {
    return a.key < b.key || (a.key == b.key && a.slot < b.slot);
  });
  PlaneCut c;
  c.segments.resize(cut.size());
  std::vector<int> point_of(2 * cut.size());
  for (std::size_t i = 0; i < ends.size(); ++i) {
    if (i == 0 || ends[i].key != ends[i - 1].key) {
      // Interpolate from the lower-index vertex so both faces get the identical point.
      const int lo = static_cast<int>(ends[i].key >> 32);
      const int hi = static_cast<int>(ends[i].key & 0xffffffffu);
      const double ya = v(lo, 1) - height, yb = v(hi, 1) - height;
      const double t = ya / (ya - yb);
      c.points.emplace_back(v(lo, 0) + t * (v(hi, 0) - v(lo, 0)),
                            v(lo, 2) + t * (v(hi, 2) - v(lo, 2)));
    }
    point_of[static_cast<std::size_t>(ends[i].slot)] = static_cast<int>(c.points.size() - 1);
  }
  c.incident.resize(c.points.size());
  for (std::size_t s = 0; s < cut.size(); ++s) {
    const int p0 = point_of[2 * s], p1 = point_of[2 * s + 1];
    c.segments[s] = {p0, p1};
    c.incident[static_cast<std::size_t>(p0)].push_back(static_cast<int>(s));
    c.incident[static_cast<std::size_t>(p1)].push_back(static_cast<int>(s));
  }
  return c;
}

// Chains the segments into loops: open chains from their ends (degree-1 points) first, then
// the closed loops; each with its length and centroid.
std::vector<SliceLoop> chain_segments(const PlaneCut& c) {
  const auto& points = c.points;
  const auto& incident = c.incident;
  const auto& segments = c.segments;
  std::vector<char> used(segments.size(), 0);
  std::vector<SliceLoop> loops;
  const auto other_end = [&](int s, int p) {
    return segments[s].first == p ? segments[s].second : segments[s].first;
  };
  const auto next_segment = [&](int p) {
    const Incident& segs = incident[static_cast<std::size_t>(p)];
    for (std::size_t i = 0; i < segs.size(); ++i) {
      if (!used[segs.at(i)]) return segs.at(i);
    }
    return -1;
  };
  // Start open chains at their ends (degree-1 points, in the order of their edge keys) first,
  // then the closed loops.
  std::vector<int> starts;
  for (std::size_t p = 0; p < incident.size(); ++p) {
    if (incident[p].size() == 1) starts.push_back(static_cast<int>(p));
  }
  for (std::size_t s0 = 0; s0 < segments.size(); ++s0) starts.push_back(segments[s0].first);
  for (int start : starts) {
    int s = next_segment(start);
    if (s < 0) continue;
    SliceLoop loop;
    int p = start;
    loop.points.push_back(points[static_cast<std::size_t>(p)]);
    while (s >= 0) {
      used[s] = 1;
      p = other_end(s, p);
      if (p == start) {
        loop.closed = true;
        break;
      }
      loop.points.push_back(points[static_cast<std::size_t>(p)]);
      s = next_segment(p);
    }
    const std::size_t m = loop.points.size();
    for (std::size_t i = 0; i + 1 < m; ++i)
      loop.length += (loop.points[i + 1] - loop.points[i]).norm();
    if (loop.closed && m > 1) loop.length += (loop.points.front() - loop.points.back()).norm();
    for (const auto& q : loop.points) loop.centroid += q;
    loop.centroid /= static_cast<double>(m);
    loops.push_back(std::move(loop));
  }
  return loops;
}

// `loop` clipped to the band lo <= x <= hi (Sutherland-Hodgman against the two lines; an
// infinite bound is no line): a closed loop stays closed, running straight along a line where it
// was cut; an open one keeps its points inside and the crossing points.
SliceLoop clip_loop_to_band(const SliceLoop& loop, double lo, double hi) {
  std::vector<Eigen::Vector2d> pts = loop.points;
  for (int side = 0; side < 2 && !pts.empty(); ++side) {
    const auto inside = [&](const Eigen::Vector2d& p) {
      return side == 0 ? p.x() >= lo : p.x() <= hi;
    };
    const double e = side == 0 ? lo : hi;
    if (!std::isfinite(e)) continue;  // no line on this side (clip_loops_left())
    std::vector<Eigen::Vector2d> out;
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& cur = pts[i];
      const Eigen::Vector2d& prev = pts[(i + n - 1) % n];
      if (inside(cur) != inside(prev) && (loop.closed || i > 0)) {
        out.push_back(prev + (e - prev.x()) / (cur.x() - prev.x()) * (cur - prev));
      }
      if (inside(cur)) out.push_back(cur);
    }
    pts = std::move(out);
  }
  SliceLoop c;
  c.points = std::move(pts);
  c.closed = loop.closed;
  const std::size_t m = c.points.size();
  for (std::size_t i = 0; i + 1 < m; ++i) c.length += (c.points[i + 1] - c.points[i]).norm();
  if (c.closed && m > 1) c.length += (c.points.front() - c.points.back()).norm();
  return c;
}

// Circumference of the loops of `loops` whose centroid x lies within [x_min, x_max]
// (circumference_between()). With a finite band band_lo < band_hi (the chest's, between the
// acromia; none when they coincide), every loop is clipped to it instead and every loop with a part
// inside counts, as long as one loop's centroid lies within [x_min, x_max]: the part of an arm
// under the plane counts up to the band whether or not it has met the torso's loop yet, so the
// girth does not jump when the plane passes the armpit.
std::optional<double> loops_circumference(
    const std::vector<SliceLoop>& loops, double x_min, double x_max, bool convex_hull,
    double band_lo = -std::numeric_limits<double>::infinity(),
    double band_hi = std::numeric_limits<double>::infinity()) {
  std::vector<Eigen::Vector2d> pts;
  double length = 0.0;
  bool any = false;
  const bool clip = std::isfinite(band_lo) && std::isfinite(band_hi) && band_hi > band_lo;
  for (const auto& l : loops) {
    const bool between = l.centroid.x() >= x_min && l.centroid.x() <= x_max;
    any = any || between;
    if (!clip) {
      if (!between) continue;
      length += l.length;
      pts.insert(pts.end(), l.points.begin(), l.points.end());
      continue;
    }
    const SliceLoop part = clip_loop_to_band(l, band_lo, band_hi);
    length += part.length;
    pts.insert(pts.end(), part.points.begin(), part.points.end());
  }
  if (!any) return std::nullopt;
  return convex_hull ? convex_hull_perimeter(pts) : length;
}

}  // namespace

std::vector<SliceLoop> slice_mesh(const smpl::Vertices& v, const smpl::Faces& faces,
                                  double height) {
  std::vector<std::vector<int>> cut;
  cut_faces(v, faces, {height}, cut);
  return chain_segments(cut_mesh(v, faces, height, cut[0]));
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
  return loops_circumference(slice_mesh(vertices, faces, height), x_min, x_max, convex_hull);
}

std::vector<Eigen::Vector2d> clip_loops_left(const std::vector<SliceLoop>& loops, double mid) {
  std::vector<Eigen::Vector2d> out;
  for (const SliceLoop& l : loops) {
    const SliceLoop part = clip_loop_to_band(l, mid, std::numeric_limits<double>::infinity());
    out.insert(out.end(), part.points.begin(), part.points.end());
  }
  return out;
}

const std::vector<std::string>& circumference_ids() {
  static const std::vector<std::string> ids = {"chest_circumference", "waist_circumference",
                                               "hip_circumference", "thigh_circumference"};
  return ids;
}

double thigh_fold_level(double fold_height, double crotch_height) {
  return std::min(fold_height, crotch_height - kThighBelowCrotch);
}

std::optional<double> thigh_fold_level(const smpl::Vertices& vertices,
                                       const LandmarkTable& landmarks) {
  const auto fold = landmarks.find("left_gluteal_fold");
  const auto crotch = landmarks.find("crotch");
  if (fold == landmarks.end() || crotch == landmarks.end()) return std::nullopt;
  return thigh_fold_level(landmark_point(vertices, fold->second).y(),
                          landmark_point(vertices, crotch->second).y());
}

MeasurementMap circumferences(const smpl::Vertices& vertices, const smpl::Faces& faces,
                              const LandmarkTable& landmarks, bool convex_hull, double thigh_drop) {
  const auto has = [&](const char* n) { return landmarks.count(n) > 0; };
  const auto pt = [&](const char* n) { return landmark_point(vertices, landmarks.at(n)); };
  // The planes first, so that one pass over the faces finds the faces each of them cuts.
  struct Level {
    const char* id;
    double height;
    double x_min, x_max;  // torso: the loops between the side landmarks
    bool thigh;           // thigh: the loop right of x_min (the crotch)
    bool fold = false;    // thigh at the gluteal fold: every point right of x_min
    // chest: the loops clipped to the band between the acromia (infinite: no clipping)
    double band_lo = -std::numeric_limits<double>::infinity();
    double band_hi = std::numeric_limits<double>::infinity();
  };
  std::vector<Level> levels;
  const auto torso = [&](const char* id, const char* at, const char* left, const char* right) {
    if (!has(at) || !has(left) || !has(right)) return;
    const double xl = pt(left).x(), xr = pt(right).x();
    levels.push_back({id, pt(at).y(), std::min(xl, xr), std::max(xl, xr), false});
  };
  torso("chest_circumference", "left_nipple", "left_chest", "right_chest");
  const bool chest = !levels.empty();  // the first level, when its landmarks are there
  if (chest && has("left_shoulder") && has("right_shoulder")) {
    const double sl = pt("left_shoulder").x(), sr = pt("right_shoulder").x();
    levels.back().band_lo = std::min(sl, sr);
    levels.back().band_hi = std::max(sl, sr);
  }
  torso("waist_circumference", "navel", "left_waist", "right_waist");
  torso("hip_circumference", "left_hip", "left_hip", "right_hip");
  torso("waist_iliac_circumference", "left_iliac_crest", "left_iliac_crest", "right_iliac_crest");
  if (has("crotch")) {
    const Eigen::Vector3d crotch = pt("crotch");
    if (const std::optional<double> fold = thigh_fold_level(vertices, landmarks)) {
      levels.push_back({"thigh_circumference", *fold, crotch.x(), 0.0, true, true});
    } else {
      levels.push_back({"thigh_circumference", crotch.y() - thigh_drop, crotch.x(), 0.0, true});
    }
  }
  MeasurementMap out;
  if (levels.empty()) return out;
  std::vector<double> heights;
  heights.reserve(levels.size());
  for (const auto& l : levels) heights.push_back(l.height);
  std::vector<std::vector<int>> cut;
  cut_faces(vertices, faces, heights, cut);
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const Level& l = levels[i];
    const auto loops = chain_segments(cut_mesh(vertices, faces, l.height, cut[i]));
    if (!l.thigh) {
      const auto c =
          loops_circumference(loops, l.x_min, l.x_max, convex_hull, l.band_lo, l.band_hi);
      if (c) out[l.id] = *c;
      continue;
    }
    if (l.fold && convex_hull) {
      const std::vector<Eigen::Vector2d> left = clip_loops_left(loops, l.x_min);
      if (left.size() >= 3) out[l.id] = convex_hull_perimeter(left);
      continue;
    }
    const SliceLoop* best = nullptr;
    for (const auto& loop : loops) {
      if (loop.centroid.x() <= l.x_min) continue;
      if (!best || loop.centroid.x() < best->centroid.x()) best = &loop;
    }
    if (best) out[l.id] = convex_hull ? convex_hull_perimeter(best->points) : best->length;
  }
  return out;
}

}  // namespace caliper
