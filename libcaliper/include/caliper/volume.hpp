/// \file volume.hpp
/// Volume of a closed triangle mesh by the divergence theorem: the sum of the signed volumes of
/// the tetrahedra (origin, a, b, c) over all faces, V = 1/6 sum a . (b x c).
#pragma once

#include "smpl/body_model.hpp"

namespace caliper {

/// Signed volume of a closed triangle mesh, m^3 (metres in, cubic metres out).
/// `vertices`: #V x 3; `faces`: #F x 3, counter-clockwise seen from outside (outward winding),
/// which gives a positive volume; inward winding gives the negated volume. Exact for closed
/// meshes whatever the origin; meaningless for open meshes (no check is made for closedness).
/// Invariant under rigid motions, scales as s^3. Several disjoint closed components add up.
/// Throws InvalidInputError if `faces` is empty, an index is out of range, or a used vertex
/// is NaN or infinite.
double mesh_volume(const smpl::Vertices& vertices, const smpl::Faces& faces);

/// Number of edges of `faces` (#F x 3) that do not close the surface: an edge is closed when it
/// is used exactly once in each direction (two consistently wound faces meet there). 0 means a
/// closed, consistently oriented surface, the condition for mesh_volume() to be a volume; an open
/// mesh (a hand cut at the wrist, a scan with holes) has its boundary edges counted here, a
/// non-manifold or inconsistently wound edge is counted too. 0 for no faces. Linear time.
long open_edge_count(const smpl::Faces& faces);

}  // namespace caliper
