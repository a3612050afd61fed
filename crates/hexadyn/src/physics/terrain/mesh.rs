//! A terrain given as a triangle mesh, queried through parry3d-f64.

use nalgebra::{Matrix3, Vector3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{TriMesh, TriMeshFlags, TrianglePointLocation};

use super::{feature_normal_jacobian, Extent, InsideNormal, Proximity, Terrain, Triangles, INSIDE_BLEND_BAND};

/// Why triangles do not make a terrain mesh.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("no faces")]
    Empty,
    #[error("vertex {index} = ({}, {}, {}): not finite", .position[0], .position[1], .position[2])]
    NonFiniteVertex { index: usize, position: [f64; 3] },
    #[error("face {face} = {indices:?}: vertex index {index} out of range (the mesh has {vertices} vertices)")]
    IndexOutOfRange { face: usize, indices: [u32; 3], index: u32, vertices: usize },
    #[error("face {face} = {indices:?}: degenerate (zero area)")]
    Degenerate { face: usize, indices: [u32; 3] },
}

fn to_parry(v: &Vector3<f64>) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

fn from_parry(v: PVec) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// A ground surface made of triangles: parry3d-f64's `TriMesh` (a BVH over the triangles)
/// answers the closest point, with the angle-weighted pseudo-normals of its edges and vertices
/// (`TriMeshFlags::ORIENTED`) deciding on which side of the surface a point is.
///
/// Above the ground the contact normal is the face's own normal when the closest point is inside
/// a face, and the direction from its closest point on an edge or a vertex to the foot: on a
/// plane tiled by triangles both are the plane's normal, so a foot sliding across the internal
/// edges feels no jump. Inside the ground it is the blend of the near faces' normals
/// ([`InsideNormal`], continuous under convex edges and vertices; the module docs). A terrain
/// is seen from above: faces whose normal points down are turned over; vertical faces keep the
/// file's orientation, which must point out of the ground
/// (counter-clockwise seen from outside, as Blender exports). The mesh must cover the ground
/// the feet reach: beyond its border there is no ground.
#[derive(Clone)]
pub struct MeshTerrain {
    mesh: TriMesh,
    /// Unit normal of each face.
    normals: Vec<PVec>,
    /// Above the highest vertex: where the vertical rays of `height_normal` start.
    top: f64,
}

impl std::fmt::Debug for MeshTerrain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MeshTerrain({} triangles, {} vertices)", self.mesh.num_triangles(), self.mesh.vertices().len())
    }
}

/// A face's normal (not normalized), `None` when degenerate.
fn face_normal(t: &Triangles, face: [u32; 3]) -> Option<Vector3<f64>> {
    let [a, b, c] = face.map(|i| Vector3::from(t.vertices[i as usize]));
    let n = (b - a).cross(&(c - a));
    // Zero area relative to the edges' lengths (collinear or repeated vertices).
    (n.norm() > 1e-12 * (b - a).norm_squared().max((c - a).norm_squared())).then_some(n)
}

impl MeshTerrain {
    /// Checks the triangles (finite vertices, indices in range, no zero-area face) and builds the
    /// mesh, faces turned to look up.
    pub fn new(mut t: Triangles) -> Result<Self, MeshError> {
        if t.faces.is_empty() {
            return Err(MeshError::Empty);
        }
        if let Some((index, position)) = t.vertices.iter().enumerate().find(|(_, v)| !v.iter().all(|x| x.is_finite())) {
            return Err(MeshError::NonFiniteVertex { index, position: *position });
        }
        let vertices = t.vertices.len();
        for face in 0..t.faces.len() {
            let indices = t.faces[face];
            if let Some(&index) = indices.iter().find(|&&i| i as usize >= vertices) {
                return Err(MeshError::IndexOutOfRange { face, indices, index, vertices });
            }
            match face_normal(&t, indices) {
                None => return Err(MeshError::Degenerate { face, indices }),
                Some(n) if n.z < 0.0 => t.faces[face] = [indices[0], indices[2], indices[1]],
                Some(_) => {}
            }
        }
        let top = t.vertices.iter().map(|v| v[2]).fold(f64::NEG_INFINITY, f64::max) + 1.0;
        let Triangles { vertices, faces } = t;
        let points = vertices.iter().map(|v| PVec::new(v[0], v[1], v[2])).collect();
        drop(vertices); // parry's copy replaces them while it builds the mesh
        let mesh = TriMesh::with_flags(points, faces, TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES).map_err(|_| MeshError::Empty)?;
        let normals = (0..mesh.num_triangles() as u32).map(|i| mesh.triangle(i).scaled_normal().normalize()).collect();
        Ok(MeshTerrain { mesh, normals, top })
    }

    pub fn triangle_count(&self) -> usize {
        self.mesh.num_triangles()
    }
}

impl Terrain for MeshTerrain {
    /// A vertical ray from above meets a face.
    fn covers(&self, x: f64, y: f64) -> bool {
        let ray = Ray::new(PVec::new(x, y, self.top), PVec::new(0.0, 0.0, -1.0));
        self.mesh.cast_local_ray(&ray, f64::MAX, false).is_some()
    }

    /// A vertical ray from above; off the mesh's footprint, the closest point's height.
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>) {
        let ray = Ray::new(PVec::new(x, y, self.top), PVec::new(0.0, 0.0, -1.0));
        match self.mesh.cast_local_ray_and_get_normal(&ray, f64::MAX, false) {
            Some(hit) => {
                let n = from_parry(hit.normal);
                (self.top - hit.time_of_impact, if n.z < 0.0 { -n } else { n })
            }
            None => {
                let above = Vector3::new(x, y, self.top);
                let closest = self.mesh.project_local_point(to_parry(&above), false).point;
                (closest.z, self.proximity(&above, 0.0).normal)
            }
        }
    }

    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        let c = to_parry(p);
        let (projection, (face, location)) = self.mesh.project_local_point_and_get_location(c, false);
        self.contact(c, face, projection.point, location, radius, None)
    }

    /// The closest face among the vicinity's when no face outside it can be closer; otherwise
    /// the search over the whole mesh, and the vicinity rebuilt around `p`.
    fn proximity_near(&self, p: &Vector3<f64>, radius: f64, vicinity: &mut Vicinity) -> Proximity {
        let c = to_parry(p);
        if let Some((face, point, location)) = vicinity.closest(&self.mesh, c) {
            return self.contact(c, face, point, location, radius, Some(vicinity));
        }
        let (projection, (face, location)) = self.mesh.project_local_point_and_get_location(c, false);
        let proximity = self.contact(c, face, projection.point, location, radius, None);
        // Inside the ground, wide enough for the faces of the normal's blend.
        let distance = radius - proximity.penetration;
        let reach = if distance < 0.0 { -(1.0 + INSIDE_BLEND_BAND) * distance } else { distance } + VICINITY_MARGIN;
        if reach <= VICINITY_MAX_REACH {
            vicinity.gather(&self.mesh, c, reach);
        } else {
            vicinity.clear();
        }
        proximity
    }

    fn triangles(&self, _extent: Extent) -> Triangles {
        Triangles { vertices: self.mesh.vertices().iter().map(|v| [v.x, v.y, v.z]).collect(), faces: self.mesh.indices().to_vec() }
    }
}

impl MeshTerrain {
    /// The contact of a foot sphere of `radius` centred at `c` whose closest point of the mesh
    /// is `point`, at `location` on `face`; inside the ground, the faces of the normal's blend
    /// are looked for among the vicinity's when it holds them all.
    fn contact(&self, c: PVec, face: u32, point: PVec, location: TrianglePointLocation, radius: f64, vicinity: Option<&Vicinity>) -> Proximity {
        let d = c - point;
        let (distance, n, curvature) = match location {
            TrianglePointLocation::OnFace(..) | TrianglePointLocation::OnSolid => {
                let n = self.normals[face as usize];
                (n.dot(d), from_parry(n), Matrix3::zeros())
            }
            TrianglePointLocation::OnEdge(..) | TrianglePointLocation::OnVertex(_) => {
                let length = d.length();
                let pseudo_normal = self.feature_pseudo_normal(face, location);
                if length > 0.0 {
                    // Inside when behind the feature's pseudo-normal (as parry3d's oriented
                    // `TriMesh` decides it).
                    let sign = if d.dot(pseudo_normal) <= 0.0 { -1.0 } else { 1.0 };
                    let n = from_parry(d * (sign / length));
                    (sign * length, n, feature_normal_jacobian(n, self.edge_direction(face, location), sign * length))
                } else {
                    (0.0, from_parry(pseudo_normal.normalize()), Matrix3::zeros())
                }
            }
        };
        let (normal, normal_jacobian) = if distance < 0.0 { self.inside_normal(c, face, InsideNormal::new(-distance, n, curvature), vicinity) } else { (n, curvature) };
        Proximity { penetration: radius - distance, normal, penetration_gradient: -n, penetration_hessian: -curvature, normal_jacobian }
    }

    /// The unit direction of the edge of `face` at `location`; `None` on a vertex.
    fn edge_direction(&self, face: u32, location: TrianglePointLocation) -> Option<Vector3<f64>> {
        let TrianglePointLocation::OnEdge(i, _) = location else {
            return None;
        };
        let t = self.mesh.triangle(face);
        // parry3d's edge numbering of `TrianglePointLocation`: AB, BC, AC.
        let (from, to) = [(t.a, t.b), (t.b, t.c), (t.a, t.c)][i as usize];
        Some(from_parry((to - from).normalize()))
    }

    /// The normal of a foot at `c` inside the ground whose closest point is on `closest`
    /// ([`InsideNormal`]) and its derivative: every face within the blend's reach takes part.
    fn inside_normal(&self, c: PVec, closest: u32, mut blend: InsideNormal, vicinity: Option<&Vicinity>) -> (Vector3<f64>, Matrix3<f64>) {
        if let Some(reach) = blend.reach() {
            blend.add_closest(closest, from_parry(self.normals[closest as usize]));
            // The projections the vicinity made for this query, then new ones.
            let projected = vicinity.map_or(&[][..], |v| &v.projected[..]);
            let mut add = |face: u32| {
                if face != closest {
                    let point = projected.iter().find(|(f, _)| *f == face).map_or_else(|| self.mesh.triangle(face).project_local_point(c, false).point, |&(_, p)| p);
                    let d = c - point;
                    let e = d.length();
                    blend.add(face, from_parry(self.normals[face as usize]), e, from_parry(d / e));
                }
            };
            match vicinity {
                Some(v) if v.holds(c, reach) => v.faces.iter().filter(|(_, aabb)| box_distance_squared(aabb, c) <= reach * reach).for_each(|&(face, _)| add(face)),
                _ => self.mesh.bvh().leaves(|node: &BvhNode| node.aabb().distance_to_local_point(c, true) <= reach).for_each(add),
            }
        }
        blend.normal()
    }

    /// The angle-weighted pseudo-normal (not normalized) of the edge or vertex of `face` at
    /// `location`.
    fn feature_pseudo_normal(&self, face: u32, location: TrianglePointLocation) -> PVec {
        let normals = self.mesh.pseudo_normals().expect("an oriented mesh has pseudo-normals");
        match location {
            TrianglePointLocation::OnEdge(i, _) => normals.edges_pseudo_normal[face as usize][i as usize],
            TrianglePointLocation::OnVertex(i) => normals.vertices_pseudo_normal[self.mesh.indices()[face as usize][i as usize] as usize],
            _ => self.normals[face as usize],
        }
    }
}

/// How far beyond a foot's closest point its [`Vicinity`] gathers faces (m): the foot may move
/// this far (less the change of its distance to the ground) before the vicinity is gathered
/// again. It sets the cost, not the answer: wider, more faces per query; narrower, more
/// searches of the whole mesh. 1 cm: a tenth of the 10 cm cells of the shipped rough ground,
/// about what a swinging foot covers in 0.2 s, while a foot on the ground moves micrometres.
const VICINITY_MARGIN: f64 = 0.01;

/// The widest [`Vicinity`] gathered (m): a foot farther from the ground (a trial state of a
/// Newton iteration that went astray, a body lifted off) would gather much of the mesh and
/// every later query would scan it; it keeps none and searches the whole mesh until it comes
/// back. 25 cm: above the highest swing of the shipped gaits (9 cm) with the margin.
const VICINITY_MAX_REACH: f64 = 0.25;

/// The squared distance from `c` to a bounding box (0 inside it).
fn box_distance_squared(aabb: &Aabb, c: PVec) -> f64 {
    (aabb.mins - c).max(c - aabb.maxs).max(PVec::ZERO).length_squared()
}

/// The faces of a mesh near one foot, kept from one query to the next
/// ([`Terrain::proximity_near`]): every face whose bounding box comes within `reach` of `centre`.
///
/// For a foot at p whose closest point among these faces is at distance d, a face closer to p
/// than d has a point within |p - centre| + d of the centre; when that is at most `reach`, the
/// face is among those gathered, so the closest of them is the closest of the mesh.
#[derive(Clone, Debug, Default)]
pub struct Vicinity {
    centre: PVec,
    pub(super) reach: f64,
    /// The faces and their bounding boxes, the closest of the last query first.
    faces: Vec<(u32, Aabb)>,
    /// The faces the last query projected the foot on, and the projections (for the inside
    /// normal's blend, which needs the same faces' distances).
    projected: Vec<(u32, PVec)>,
}

impl Vicinity {
    /// The closest point of the gathered faces to `c` (face, point, location) when it is the
    /// closest of the whole mesh (type docs) and no other gathered face is as close; `None`
    /// otherwise.
    fn closest(&mut self, mesh: &TriMesh, c: PVec) -> Option<(u32, PVec, TrianglePointLocation)> {
        let mut best: Option<(usize, PVec, TrianglePointLocation)> = None;
        let mut best_distance = f64::MAX;
        // Two faces at exactly the closest distance (the closest point on their common edge):
        // parry3d's search keeps the first it visits, so the vicinity leaves the choice to it.
        let mut tie = false;
        self.projected.clear();
        for (k, (face, aabb)) in self.faces.iter().enumerate() {
            // A face whose box is farther than the closest point so far cannot be closer (the
            // relative slack covers the rounding of both distances).
            if box_distance_squared(aabb, c) > best_distance * best_distance * (1.0 + 1e-9) {
                continue;
            }
            let (projection, location) = mesh.triangle(*face).project_local_point_and_get_location(c, false);
            self.projected.push((*face, projection.point));
            let distance = (projection.point - c).length();
            if distance < best_distance {
                best = Some((k, projection.point, location));
                best_distance = distance;
                tie = false;
            } else {
                tie |= distance == best_distance;
            }
        }
        if tie || !self.holds(c, best_distance) {
            return None;
        }
        let (k, point, location) = best?;
        // The next query, a little further along, starts from this face.
        self.faces.swap(0, k);
        Some((self.faces[0].0, point, location))
    }

    /// Whether every face with a point within `distance` of `c` is gathered (type docs).
    fn holds(&self, c: PVec, distance: f64) -> bool {
        // A nanometre of slack for the rounding of the bounding boxes' distances.
        c.distance(self.centre) + distance <= self.reach - 1e-9
    }

    /// Keeps no face: the next query searches the whole mesh.
    fn clear(&mut self) {
        self.reach = 0.0;
        self.faces.clear();
        self.projected.clear();
    }

    /// Gathers the faces whose bounding box comes within `reach` of `centre`.
    fn gather(&mut self, mesh: &TriMesh, centre: PVec, reach: f64) {
        self.centre = centre;
        self.reach = reach;
        self.faces.clear();
        self.projected.clear();
        let within = |node: &BvhNode| node.aabb().distance_to_local_point(centre, true) <= reach;
        self.faces.extend(mesh.bvh().leaves(within).map(|face| (face, mesh.triangle(face).local_aabb())));
    }
}
