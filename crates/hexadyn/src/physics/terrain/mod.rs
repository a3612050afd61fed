//! The ground the feet walk on (thesis Sections 3.4.2 and 7.7.5): flat, a plane slope, an
//! analytic step, a heightfield and triangle meshes read from PLY files, behind one
//! [`Terrain`] interface.
//!
//! The contact of Eq. 3.72-3.73 needs, for a foot, its penetration δ and the unit normal n
//! along which the normal force acts. The thesis' foot is a point against the tangent plane
//! below it (Section 3.4.2); its stiffness is the Hertz law of a sphere on a half space
//! (Eq. 3.74). On a terrain with edges (a step, a mesh) the tangent plane below the foot jumps
//! at the edge, so every terrain here answers by closest point: for a foot sphere of radius r
//! centred at p, the closest point s of the ground surface gives the signed distance d of p
//! (positive above the ground, negative inside it), δ = r - d, and n, the unit vector from s to p
//! (from p to s when p is inside), or the surface's normal where p lies on it. With r = 0 this is
//! the thesis' point foot; on a plane it is exactly its tangent-plane law.
//!
//! - [`FlatGround`], [`Slope`]: planes (analytic);
//! - [`Step`]: two horizontal half planes joined by a vertical face (analytic closest point);
//! - [`MeshTerrain`]: a triangle mesh (parry3d-f64's `TriMesh` with its BVH and the
//!   angle-weighted pseudo-normals of its edges and vertices), from a PLY file ([`ply`]);
//! - [`Heightfield`]: heights on a regular grid, its height under a point by the cell's triangle
//!   and its contact through the mesh of those triangles;
//! - [`generate`]: the seeded terrains the shipped scenarios use (a step, a ramp, rough ground);
//! - [`classes`]: terrain classes (steps, slopes, rough ground by size) drawn from seeds.

mod heightfield;
mod mesh;
mod step;

pub mod classes;
pub mod generate;
pub mod ply;

pub use heightfield::Heightfield;
pub use mesh::{MeshError, MeshTerrain, Vicinity};
pub use step::Step;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The contact geometry of a foot sphere with the ground (closest point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proximity {
    /// δ = r - d: the overlap of the foot sphere (radius r) with the ground, d the signed
    /// distance of its centre to the surface (> 0 above it); negative: the clearance (m).
    pub penetration: f64,
    /// Unit normal n of the contact, out of the ground towards the foot.
    pub normal: Vector3<f64>,
}

/// Triangles of a terrain's surface (vertices in m, faces counter-clockwise seen from above, so
/// that their normals point out of the ground).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Triangles {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Vec<[u32; 3]>,
}

/// A horizontal square, the part of an unbounded terrain that is drawn or meshed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    /// Centre (x, y) (m).
    pub centre: [f64; 2],
    /// Half the side (m).
    pub half_width: f64,
}

/// A ground surface.
pub trait Terrain: std::fmt::Debug + Send + Sync {
    /// Height h of the ground below (x, y), where a vertical line first meets it from above, and
    /// its unit normal n there, pointing out of the ground (n_z > 0).
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>);

    /// Closest-point contact of a foot sphere of `radius` centred at `p` (module docs).
    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity;

    /// The same contact as [`Terrain::proximity`], for a foot that keeps its [`Vicinity`] from
    /// one query to the next: a terrain that searches for the closest point (a mesh) looks
    /// first among the faces it found near the foot's last position. The answer does not depend
    /// on the vicinity (only its cost does); the analytic terrains ignore it.
    fn proximity_near(&self, p: &Vector3<f64>, radius: f64, _vicinity: &mut Vicinity) -> Proximity {
        self.proximity(p, radius)
    }

    /// The surface as triangles: a mesh's own; an analytic terrain's within `extent`.
    fn triangles(&self, extent: Extent) -> Triangles;
}

/// Horizontal ground at z = `height`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlatGround {
    pub height: f64,
}

impl Terrain for FlatGround {
    fn height_normal(&self, _x: f64, _y: f64) -> (f64, Vector3<f64>) {
        (self.height, Vector3::z())
    }
    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        plane_proximity(self, p, radius)
    }
    fn triangles(&self, extent: Extent) -> Triangles {
        plane_triangles(self, extent)
    }
}

/// Inclined plane z = height + slope_x x + slope_y y.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Slope {
    pub height: f64,
    /// ∂h/∂x.
    pub slope_x: f64,
    /// ∂h/∂y.
    pub slope_y: f64,
}

impl Slope {
    /// A plane through (0, 0, `height`) rising at `angle` (rad) in the horizontal direction
    /// `azimuth` (rad from x_0 about z_0).
    pub fn from_angle(height: f64, angle: f64, azimuth: f64) -> Self {
        let t = angle.tan();
        Slope { height, slope_x: t * azimuth.cos(), slope_y: t * azimuth.sin() }
    }
}

impl Terrain for Slope {
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>) {
        (self.height + self.slope_x * x + self.slope_y * y, Vector3::new(-self.slope_x, -self.slope_y, 1.0).normalize())
    }
    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        plane_proximity(self, p, radius)
    }
    fn triangles(&self, extent: Extent) -> Triangles {
        plane_triangles(self, extent)
    }
}

/// A plane's contact: the distance of p to the tangent plane at p_s = (x, y, h(x, y)),
/// δ = n · (p_s - p) + r = n_z (h - p_z) + r (Section 3.4.2: a point against a plane).
fn plane_proximity(plane: &dyn Terrain, p: &Vector3<f64>, radius: f64) -> Proximity {
    let (h, n) = plane.height_normal(p.x, p.y);
    Proximity { penetration: n.z * (h - p.z) + radius, normal: n }
}

/// Two triangles covering a plane over `extent`.
fn plane_triangles(plane: &dyn Terrain, extent: Extent) -> Triangles {
    let ([cx, cy], w) = (extent.centre, extent.half_width);
    let corner = |x: f64, y: f64| [x, y, plane.height_normal(x, y).0];
    Triangles {
        vertices: vec![corner(cx - w, cy - w), corner(cx + w, cy - w), corner(cx + w, cy + w), corner(cx - w, cy + w)],
        faces: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[cfg(test)]
mod tests;
