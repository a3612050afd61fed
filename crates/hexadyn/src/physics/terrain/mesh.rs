//! A terrain given as a triangle mesh, queried through parry3d-f64.

use nalgebra::Vector3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{TriMesh, TriMeshFlags, TrianglePointLocation};

use super::{Extent, Proximity, Terrain, Triangles};

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
/// The contact normal is the face's own normal when the closest point is inside a face, and the
/// direction between the foot and its closest point on an edge or a vertex: on a plane tiled
/// by triangles both are the plane's normal, so a foot sliding across the internal edges feels
/// no jump. A terrain is seen from above: faces whose normal points down are turned over;
/// vertical faces keep the file's orientation, which must point out of the ground
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
        let points = t.vertices.iter().map(|v| PVec::new(v[0], v[1], v[2])).collect();
        let mesh = TriMesh::with_flags(points, t.faces, TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES).map_err(|_| MeshError::Empty)?;
        let normals = (0..mesh.num_triangles() as u32).map(|i| mesh.triangle(i).scaled_normal().normalize()).collect();
        Ok(MeshTerrain { mesh, normals, top })
    }

    pub fn triangle_count(&self) -> usize {
        self.mesh.num_triangles()
    }
}

impl Terrain for MeshTerrain {
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
        let d = c - projection.point;
        let (distance, n) = match location {
            TrianglePointLocation::OnFace(..) | TrianglePointLocation::OnSolid => {
                let n = self.normals[face as usize];
                (n.dot(d), n)
            }
            TrianglePointLocation::OnEdge(..) | TrianglePointLocation::OnVertex(_) => {
                let length = d.length();
                if length > 0.0 {
                    let sign = if projection.is_inside { -1.0 } else { 1.0 };
                    (sign * length, d * (sign / length))
                } else {
                    (0.0, self.feature_pseudo_normal(face, location))
                }
            }
        };
        Proximity { penetration: radius - distance, normal: from_parry(n) }
    }

    fn triangles(&self, _extent: Extent) -> Triangles {
        Triangles { vertices: self.mesh.vertices().iter().map(|v| [v.x, v.y, v.z]).collect(), faces: self.mesh.indices().to_vec() }
    }
}

impl MeshTerrain {
    /// The unit pseudo-normal of the edge or vertex of `face` at `location`.
    fn feature_pseudo_normal(&self, face: u32, location: TrianglePointLocation) -> PVec {
        let normals = self.mesh.pseudo_normals().expect("an oriented mesh has pseudo-normals");
        let n = match location {
            TrianglePointLocation::OnEdge(i, _) => normals.edges_pseudo_normal[face as usize][i as usize],
            TrianglePointLocation::OnVertex(i) => normals.vertices_pseudo_normal[self.mesh.indices()[face as usize][i as usize] as usize],
            _ => self.normals[face as usize],
        };
        n.normalize()
    }
}
