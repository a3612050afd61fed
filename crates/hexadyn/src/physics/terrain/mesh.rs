//! A terrain given as a triangle mesh: its faces found through a grid over the ground
//! (`face_grid.rs`), each face queried through parry3d-f64's `Triangle`.

use nalgebra::{Matrix3, Vector3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Vector as PVec, VectorExt};
use parry3d_f64::query::{PointQuery, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{Triangle, TrianglePointLocation};

use super::face_grid::FaceGrid;
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

/// A ground surface made of triangles: the faces listed by the cells of a grid over the XY
/// plane ([`FaceGrid`]) find the closest point, each face's own geometry (closest point and
/// ray) is parry3d-f64's `Triangle`, and the angle-weighted pseudo-normals of its edges and
/// vertices (parry3d's `TriMeshFlags::ORIENTED` definition, summed in the same order) decide on
/// which side of the surface a point is. They are computed when a foot's closest point is on
/// an edge or a vertex, from the faces around each vertex, not stored: the mesh holds its
/// vertices, faces, the faces around each vertex and the grid, about 50 bytes a face (issue
/// 39; parry3d's `TriMesh` with its BVH and stored pseudo-normals took about 260, 446 at the
/// peak of its building).
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
    /// The vertices, those at the same coordinates merged into one, in the order the faces
    /// first use them (as parry3d's `TriMeshFlags::MERGE_DUPLICATE_VERTICES`).
    vertices: Vec<PVec>,
    faces: Vec<[u32; 3]>,
    /// The faces around each vertex in ascending order, vertex after vertex, and where each
    /// vertex's start (one more than the vertices).
    ring_faces: Vec<u32>,
    ring_starts: Vec<u32>,
    grid: FaceGrid,
    /// Above the highest vertex: where the vertical rays of `height_normal` start.
    top: f64,
}

impl std::fmt::Debug for MeshTerrain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MeshTerrain({} triangles, {} vertices)", self.faces.len(), self.vertices.len())
    }
}

/// A face's normal (not normalized), `None` when degenerate.
fn face_normal(t: &Triangles, face: [u32; 3]) -> Option<Vector3<f64>> {
    let [a, b, c] = face.map(|i| Vector3::from(t.vertices[i as usize]));
    let n = (b - a).cross(&(c - a));
    // Zero area relative to the edges' lengths (collinear or repeated vertices).
    (n.norm() > 1e-12 * (b - a).norm_squared().max((c - a).norm_squared())).then_some(n)
}

/// Merges the vertices at bitwise equal coordinates and drops the unused ones, numbering them in
/// the order the faces first use them (parry3d's `merge_duplicate_vertices`, by sorting instead
/// of hashing: 8 bytes a vertex while it runs).
fn merge_duplicate_vertices(vertices: Vec<[f64; 3]>, faces: &mut [[u32; 3]]) -> Vec<PVec> {
    let key = |v: usize| vertices[v].map(f64::to_bits);
    // For each vertex, the first of its group of equal coordinates.
    let mut first: Vec<u32> = (0..vertices.len() as u32).collect();
    first.sort_unstable_by_key(|&v| (key(v as usize), v));
    let mut representative = vec![0u32; vertices.len()];
    for k in 0..first.len() {
        let v = first[k] as usize;
        representative[v] = if k > 0 && key(first[k - 1] as usize) == key(v) { representative[first[k - 1] as usize] } else { v as u32 };
    }
    // The new numbers, in the order of first use (u32::MAX: not numbered yet).
    let mut number = first;
    number.fill(u32::MAX);
    let mut merged = Vec::new();
    for face in faces.iter_mut() {
        for i in face.iter_mut() {
            let r = representative[*i as usize] as usize;
            if number[r] == u32::MAX {
                number[r] = merged.len() as u32;
                let [x, y, z] = vertices[r];
                merged.push(PVec::new(x, y, z));
            }
            *i = number[r];
        }
    }
    merged.shrink_to_fit();
    merged
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
        let Triangles { vertices, mut faces } = t;
        let vertices = merge_duplicate_vertices(vertices, &mut faces);
        faces.shrink_to_fit();
        // The faces around each vertex: counts, offsets, then the faces in ascending order.
        let mut ring_starts = vec![0u32; vertices.len() + 1];
        faces.iter().flatten().for_each(|&v| ring_starts[v as usize + 1] += 1);
        for v in 1..ring_starts.len() {
            ring_starts[v] += ring_starts[v - 1];
        }
        let mut next = ring_starts.clone();
        let mut ring_faces = vec![0u32; 3 * faces.len()];
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                ring_faces[next[v as usize] as usize] = f as u32;
                next[v as usize] += 1;
            }
        }
        drop(next);
        let grid = FaceGrid::new(faces.len(), |f| {
            let [a, b, c] = faces[f as usize].map(|v| vertices[v as usize]);
            let (low, high) = (a.min(b).min(c), a.max(b).max(c));
            [low.x, low.y, low.z, high.x, high.y, high.z]
        });
        Ok(MeshTerrain { vertices, faces, ring_faces, ring_starts, grid, top })
    }

    pub fn triangle_count(&self) -> usize {
        self.faces.len()
    }

    /// The bytes the mesh holds (its vertices, faces, rings and grid).
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<PVec>() * self.vertices.len() + 12 * self.faces.len() + 4 * (self.ring_faces.len() + self.ring_starts.len()) + self.grid.bytes()
    }

    fn triangle(&self, face: u32) -> Triangle {
        let [a, b, c] = self.faces[face as usize].map(|v| self.vertices[v as usize]);
        Triangle::new(a, b, c)
    }

    /// The unit normal of `face`.
    fn normal(&self, face: u32) -> PVec {
        self.triangle(face).scaled_normal().normalize()
    }

    /// The faces around vertex `v`, in ascending order.
    fn ring(&self, v: u32) -> &[u32] {
        &self.ring_faces[self.ring_starts[v as usize] as usize..self.ring_starts[v as usize + 1] as usize]
    }

    /// The closest point of the mesh to `c`: (face, point, location). Of faces at the same
    /// distance, the first the rings of the grid visit.
    fn closest(&self, c: PVec) -> (u32, PVec, TrianglePointLocation) {
        let mut best: Option<(u32, PVec, TrianglePointLocation)> = None;
        let mut best_distance = f64::INFINITY;
        self.grid.rings([c.x, c.y, c.z], |faces| {
            for &face in faces {
                let t = self.triangle(face);
                // A face whose box is farther than the closest point so far cannot be closer (the
                // relative slack covers the rounding of both distances).
                if box_distance_squared(&t.local_aabb(), c) > best_distance * best_distance * (1.0 + 1e-9) {
                    continue;
                }
                let (projection, location) = t.project_local_point_and_get_location(c, false);
                let distance = (projection.point - c).length();
                if distance < best_distance {
                    best = Some((face, projection.point, location));
                    best_distance = distance;
                }
            }
            best_distance
        });
        // A point that is not finite is at no finite distance: its projection on the first face.
        best.unwrap_or_else(|| {
            let (projection, location) = self.triangle(0).project_local_point_and_get_location(c, false);
            (0, projection.point, location)
        })
    }

    /// The faces whose bounding box comes within `reach` of `c`, in ascending order.
    fn faces_within(&self, c: PVec, reach: f64) -> Vec<u32> {
        let mut faces = Vec::new();
        self.grid.near([c.x, c.y, c.z], reach, |f| faces.push(f));
        faces.sort_unstable();
        faces.dedup();
        faces.retain(|&f| box_distance_squared(&self.triangle(f).local_aabb(), c) <= reach * reach);
        faces
    }

    /// The first face a vertical ray down from above (x, y) meets: (time of impact, its normal).
    fn ray_down(&self, x: f64, y: f64) -> Option<(f64, PVec)> {
        let ray = Ray::new(PVec::new(x, y, self.top), PVec::new(0.0, 0.0, -1.0));
        let mut hit: Option<(f64, PVec)> = None;
        for &face in self.grid.at(x, y) {
            let t = self.triangle(face);
            // A face whose footprint is a nanometre or more away cannot be hit (the ray cast's
            // rounding is far finer); most of a cell's faces are spared the cast.
            let outside = |u: f64, a: f64, b: f64, c: f64| u < a.min(b).min(c) - 1e-9 || u > a.max(b).max(c) + 1e-9;
            if outside(x, t.a.x, t.b.x, t.c.x) || outside(y, t.a.y, t.b.y, t.c.y) {
                continue;
            }
            if let Some(h) = t.cast_local_ray_and_get_normal(&ray, f64::MAX, false) {
                if hit.is_none_or(|(time, _)| h.time_of_impact < time) {
                    hit = Some((h.time_of_impact, h.normal));
                }
            }
        }
        hit
    }
}

impl Terrain for MeshTerrain {
    /// A vertical ray from above meets a face.
    fn covers(&self, x: f64, y: f64) -> bool {
        self.ray_down(x, y).is_some()
    }

    /// A vertical ray from above; off the mesh's footprint, the closest point's height.
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>) {
        match self.ray_down(x, y) {
            Some((time_of_impact, normal)) => {
                let n = from_parry(normal);
                (self.top - time_of_impact, if n.z < 0.0 { -n } else { n })
            }
            None => {
                let above = Vector3::new(x, y, self.top);
                let closest = self.closest(to_parry(&above)).1;
                (closest.z, self.proximity(&above, 0.0).normal)
            }
        }
    }

    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        let c = to_parry(p);
        let (face, point, location) = self.closest(c);
        self.contact(c, face, point, location, radius, None)
    }

    /// The closest face among the vicinity's when no face outside it can be closer; otherwise
    /// the search over the whole mesh, and the vicinity rebuilt around `p`.
    fn proximity_near(&self, p: &Vector3<f64>, radius: f64, vicinity: &mut Vicinity) -> Proximity {
        let c = to_parry(p);
        if let Some((face, point, location)) = vicinity.closest(self, c) {
            return self.contact(c, face, point, location, radius, Some(vicinity));
        }
        let (face, point, location) = self.closest(c);
        let proximity = self.contact(c, face, point, location, radius, None);
        // Inside the ground, wide enough for the faces of the normal's blend.
        let distance = radius - proximity.penetration;
        let reach = if distance < 0.0 { -(1.0 + INSIDE_BLEND_BAND) * distance } else { distance } + VICINITY_MARGIN;
        if reach <= VICINITY_MAX_REACH {
            vicinity.gather(self, c, reach);
        } else {
            vicinity.clear();
        }
        proximity
    }

    fn triangles(&self, _extent: Extent) -> Triangles {
        Triangles { vertices: self.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(), faces: self.faces.clone() }
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
                let n = self.normal(face);
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
        let t = self.triangle(face);
        // parry3d's edge numbering of `TrianglePointLocation`: AB, BC, AC.
        let (from, to) = [(t.a, t.b), (t.b, t.c), (t.a, t.c)][i as usize];
        Some(from_parry((to - from).normalize()))
    }

    /// The normal of a foot at `c` inside the ground whose closest point is on `closest`
    /// ([`InsideNormal`]) and its derivative: every face within the blend's reach takes part.
    fn inside_normal(&self, c: PVec, closest: u32, mut blend: InsideNormal, vicinity: Option<&Vicinity>) -> (Vector3<f64>, Matrix3<f64>) {
        if let Some(reach) = blend.reach() {
            blend.add_closest(closest, from_parry(self.normal(closest)));
            // The projections the vicinity made for this query, then new ones.
            let projected = vicinity.map_or(&[][..], |v| &v.projected[..]);
            let mut add = |face: u32| {
                if face != closest {
                    let point = projected.iter().find(|(f, _)| *f == face).map_or_else(|| self.triangle(face).project_local_point(c, false).point, |&(_, p)| p);
                    let d = c - point;
                    let e = d.length();
                    blend.add(face, from_parry(self.normal(face)), e, from_parry(d / e));
                }
            };
            match vicinity {
                Some(v) if v.holds(c, reach) => v.faces.iter().filter(|(_, aabb)| box_distance_squared(aabb, c) <= reach * reach).for_each(|&(face, _)| add(face)),
                _ => self.faces_within(c, reach).into_iter().for_each(add),
            }
        }
        blend.normal()
    }

    /// The angle-weighted pseudo-normal (not normalized) of the edge or vertex of `face` at
    /// `location`.
    fn feature_pseudo_normal(&self, face: u32, location: TrianglePointLocation) -> PVec {
        // Parry3d's `TriMesh::compute_pseudo_normals`: the faces' unit normals, times the
        // face's angle at a vertex, summed over the faces in ascending order.
        let unit = |f: u32| self.triangle(f).normal().expect("no degenerate face (MeshTerrain::new)");
        let indices = self.faces[face as usize];
        match location {
            TrianglePointLocation::OnEdge(i, _) => {
                // TrianglePointLocation's edges: AB, BC, AC.
                let (a, b) = [(indices[0], indices[1]), (indices[1], indices[2]), (indices[0], indices[2])][i as usize];
                self.ring(a).iter().filter(|&&f| self.faces[f as usize].contains(&b)).fold(PVec::ZERO, |n, &f| n + unit(f))
            }
            TrianglePointLocation::OnVertex(i) => {
                let v = indices[i as usize];
                self.ring(v).iter().fold(PVec::ZERO, |n, &f| {
                    let t = self.triangle(f);
                    let angle = match self.faces[f as usize].iter().position(|&w| w == v) {
                        Some(0) => (t.b - t.a).angle(t.c - t.a),
                        Some(1) => (t.a - t.b).angle(t.c - t.b),
                        _ => (t.b - t.c).angle(t.a - t.c),
                    };
                    n + unit(f) * angle
                })
            }
            _ => self.normal(face),
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
    fn closest(&mut self, mesh: &MeshTerrain, c: PVec) -> Option<(u32, PVec, TrianglePointLocation)> {
        let mut best: Option<(usize, PVec, TrianglePointLocation)> = None;
        let mut best_distance = f64::MAX;
        // Two faces at exactly the closest distance (the closest point on their common edge):
        // the mesh's search (`MeshTerrain::closest`) keeps the first it visits, so the vicinity
        // leaves the choice to it.
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
    fn gather(&mut self, mesh: &MeshTerrain, centre: PVec, reach: f64) {
        self.centre = centre;
        self.reach = reach;
        self.faces.clear();
        self.projected.clear();
        self.faces.extend(mesh.faces_within(centre, reach).into_iter().map(|face| (face, mesh.triangle(face).local_aabb())));
    }
}

#[cfg(test)]
mod tests {
    use parry3d_f64::shape::{TriMesh, TriMeshFlags};
    use rand::Rng;

    use super::*;
    use crate::physics::terrain::generate;
    use crate::test_util::rng;

    /// Against parry3d's oriented `TriMesh` (the structure it replaces) on the shipped terrains
    /// and a boulder field: the same merged vertices and faces, the same closest distance, and
    /// on edges and vertices the same pseudo-normals, bit for bit; the same vertical rays.
    #[test]
    fn closest_points_and_pseudo_normals_are_parrys() {
        let mut rng = rng(39);
        let mut terrains = generate::shipped();
        terrains.push(("boulders", generate::boulders(0.03, 2)));
        for (name, t) in terrains {
            let mesh = MeshTerrain::new(t).unwrap();
            let oracle = TriMesh::with_flags(mesh.vertices.clone(), mesh.faces.clone(), TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES).unwrap();
            assert_eq!((oracle.vertices(), oracle.indices()), (&mesh.vertices[..], &mesh.faces[..]), "{name}");
            let normals = oracle.pseudo_normals().unwrap();
            let aabb = oracle.local_aabb();
            let (mut edges, mut vertices) = (0, 0);
            for _ in 0..4000 {
                let c = PVec::new(rng.random_range(aabb.mins.x - 0.5..aabb.maxs.x + 0.5), rng.random_range(aabb.mins.y - 0.5..aabb.maxs.y + 0.5), rng.random_range(aabb.mins.z - 0.2..aabb.maxs.z + 0.3));
                let (face, point, location) = mesh.closest(c);
                let (projection, (oracle_face, oracle_location)) = oracle.project_local_point_and_get_location(c, false);
                assert_eq!((point - c).length(), (projection.point - c).length(), "{name} at {c}: face {face} against {oracle_face}");
                if face == oracle_face && format!("{location:?}") == format!("{oracle_location:?}") {
                    let expected = match location {
                        TrianglePointLocation::OnEdge(i, _) => normals.edges_pseudo_normal[face as usize][i as usize],
                        TrianglePointLocation::OnVertex(i) => normals.vertices_pseudo_normal[mesh.faces[face as usize][i as usize] as usize],
                        _ => mesh.normal(face),
                    };
                    edges += matches!(location, TrianglePointLocation::OnEdge(..)) as usize;
                    vertices += matches!(location, TrianglePointLocation::OnVertex(_)) as usize;
                    assert_eq!(mesh.feature_pseudo_normal(face, location), expected, "{name} at {c}");
                }
                let ray = Ray::new(PVec::new(c.x, c.y, mesh.top), PVec::new(0.0, 0.0, -1.0));
                assert_eq!(mesh.ray_down(c.x, c.y).map(|(time, _)| time), oracle.cast_local_ray(&ray, f64::MAX, false), "{name} at {c}");
            }
            assert!(edges > 100 && vertices > 10, "{name}: {edges} edges and {vertices} vertices checked");
        }
    }

    /// The mesh holds a few times its data: on a grid of 2 triangles a vertex, at most 60 bytes a
    /// triangle (24 a vertex, 12 a face, 12 in the vertices' rings, the grid's cells).
    #[test]
    fn a_mesh_holds_a_few_times_its_data() {
        let mesh = MeshTerrain::new(generate::rough(0.015, 7)).unwrap();
        let per_triangle = mesh.bytes() as f64 / mesh.triangle_count() as f64;
        assert!(per_triangle < 60.0, "{per_triangle} bytes a triangle");
    }
}
