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
//! Inside the ground the closest face changes on the bisector of a convex edge (a ridge, the
//! top corner of a step), where the closest-point normal jumps by the edge's dihedral angle and
//! a point foot resting there feels a force jump. INTERPRETATION (the thesis' foot is a point
//! against the tangent plane below it, which has no answer at an edge): inside the ground the
//! normal is the faces' normals weighted by how near each face is compared with the closest
//! ([`InsideNormal`]): a face at distance e from a foot whose closest face is at e_min weighs
//! φ((e - e_min) / (β e_min)), φ(u) = (1 - u)² (1 + 2u) on [0, 1] and 0 beyond, β = 1
//! ([`INSIDE_BLEND_BAND`]). The normal turns continuously (C¹ in e) from one face's over the
//! bisector, where it is their mean, to the other's; on a face farther than 2 e_min from every
//! other face, and on a plane tiled by triangles, it is the face's normal. The penetration
//! stays the exact distance: the force is continuous, its spring not exactly conservative
//! inside the band (a foot would have to circle around the edge within it, sub-millimetre, to
//! gain or lose energy).
//!
//! - [`FlatGround`], [`Slope`]: planes (analytic);
//! - [`Step`]: two horizontal half planes joined by a vertical face (analytic closest point);
//! - [`MeshTerrain`]: a triangle mesh (its faces found through a grid over the ground, each
//!   face's closest point by parry3d-f64's `Triangle`, the angle-weighted pseudo-normals of its
//!   edges and vertices computed from the faces around them), from a PLY file ([`ply`]);
//! - [`Heightfield`]: heights on a regular grid, its height under a point by the cell's triangle
//!   and its contact through the mesh of those triangles;
//! - [`generate`]: the seeded terrains the shipped scenarios use (a step, a ramp, rough ground);
//! - [`classes`]: terrain classes (steps, slopes, rough ground by size) drawn from seeds.

mod face_grid;
mod heightfield;
mod mesh;
mod step;

pub mod classes;
pub mod generate;
pub mod ply;

pub use heightfield::Heightfield;
pub use mesh::{MeshError, MeshTerrain, Vicinity};
pub use step::Step;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The contact geometry of a foot sphere with the ground (closest point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proximity {
    /// δ = r - d: the overlap of the foot sphere (radius r) with the ground, d the signed
    /// distance of its centre to the surface (> 0 above it); negative: the clearance (m).
    pub penetration: f64,
    /// Unit normal n of the contact, out of the ground towards the foot.
    pub normal: Vector3<f64>,
    /// ∇δ = ∂δ/∂p: minus the closest-point normal n_c, the unit vector between the foot and
    /// its closest point (-n on a face; inside the ground n is the blend of the module docs,
    /// n_c is not).
    pub penetration_gradient: Vector3<f64>,
    /// ∂∇δ/∂p = -∂n_c/∂p: zero on a face; where the closest point is on an edge or a vertex,
    /// the turning of n_c as the foot moves around it ([`feature_normal_jacobian`]).
    pub penetration_hessian: Matrix3<f64>,
    /// ∂n/∂p: ∂n_c/∂p above the ground, the blend's derivative inside it.
    pub normal_jacobian: Matrix3<f64>,
}

/// ∂n_c/∂p for a foot at signed distance `distance` (> 0 above the ground) from its closest
/// point on an edge along the unit vector `edge` or on a vertex (`None`), n_c the unit vector
/// from that point to the foot above the ground (from the foot to it inside):
/// (I - n_c n_cᵀ - t tᵀ) / distance, the closest point sliding along the edge.
pub(crate) fn feature_normal_jacobian(normal: Vector3<f64>, edge: Option<Vector3<f64>>, distance: f64) -> Matrix3<f64> {
    let along = edge.map_or(Matrix3::zeros(), |t| t * t.transpose());
    (Matrix3::identity() - normal * normal.transpose() - along) / distance
}

/// β of the inside normal's blend (module docs): faces within (1 + β) times the closest
/// distance take part. 1: the normal turns over a band as wide as the penetration itself,
/// about a millimetre for a foot carrying its share of AMRU5 on the ground of Table 3.3, far
/// wider than what a foot on the ground moves in a step.
pub const INSIDE_BLEND_BAND: f64 = 1.0;

/// Depth (m) beyond which the inside normal's blend fades back to the closest-point normal,
/// which it reaches at twice this depth. A point far inside the ground is about as far from
/// every face of a small mesh, so the blend would take them all: a state the solvers may try
/// on their way (a Newton step through a singular stiffness), not one the contact law
/// describes. INTERPRETATION: 5 cm, above any Hertz penetration the shipped grounds give (a few
/// millimetres on Table 3.3's, 3 cm on the soft ground of the enhanced-foot scenarios).
pub const INSIDE_BLEND_DEPTH: f64 = 0.05;

/// φ(u) = (1 - u)² (1 + 2u) on [0, 1], 1 below, 0 above, and φ'(u).
fn smooth_step_down(u: f64) -> (f64, f64) {
    if u <= 0.0 {
        (1.0, 0.0)
    } else if u >= 1.0 {
        (0.0, 0.0)
    } else {
        ((1.0 - u) * (1.0 - u) * (1.0 + 2.0 * u), -6.0 * u * (1.0 - u))
    }
}

/// The normal of a foot inside the ground, at depth e_min > 0 under its closest face, blended
/// from the normals of the faces near it (module docs). Faces with the same normal (coplanar
/// tiles of one face) count once, with the largest of their weights, so that how a face is
/// cut into triangles does not matter. The blend does not depend on the order the faces come
/// in: each normal is represented by its face of lowest key, and the sum runs in key order.
pub(crate) struct InsideNormal {
    depth: f64,
    /// The closest-point normal n_c (∇e_min = -n_c) and ∂n_c/∂p.
    closest: (Vector3<f64>, Matrix3<f64>),
    /// The fade to n_c with the depth ([`INSIDE_BLEND_DEPTH`]) and its derivative in the depth.
    fade: (f64, f64),
    /// Distinct normals: (key of the face representing it, unit normal, weight, its gradient).
    normals: [(u32, Vector3<f64>, f64, Vector3<f64>); 6],
    len: usize,
    /// The weighted normals of more distinct faces than `normals` holds (not grouped), and
    /// their derivative ∂/∂p.
    overflow: (Vector3<f64>, Matrix3<f64>),
}

impl InsideNormal {
    /// A foot at depth e_min under its closest point, whose normal n_c is `closest` with
    /// ∂n_c/∂p = `closest_jacobian`.
    pub(crate) fn new(depth: f64, closest: Vector3<f64>, closest_jacobian: Matrix3<f64>) -> Self {
        let (fade, slope) = smooth_step_down(depth / INSIDE_BLEND_DEPTH - 1.0);
        InsideNormal {
            depth,
            closest: (closest, closest_jacobian),
            fade: (fade, slope / INSIDE_BLEND_DEPTH),
            normals: [(0, Vector3::zeros(), 0.0, Vector3::zeros()); 6],
            len: 0,
            overflow: (Vector3::zeros(), Matrix3::zeros()),
        }
    }

    /// How far from the foot a face can take part, (1 + β) e_min; `None` when the blend has
    /// faded out (no face takes part).
    pub(crate) fn reach(&self) -> Option<f64> {
        (self.fade.0 > 0.0).then_some((1.0 + INSIDE_BLEND_BAND) * self.depth)
    }

    /// The closest face, of key `key` and unit normal `normal`: weight 1, no gradient (u = 0).
    pub(crate) fn add_closest(&mut self, key: u32, normal: Vector3<f64>) {
        self.add(key, normal, self.depth, -self.closest.0);
    }

    /// The face of key `key` (its index), unit normal `normal`, at `distance` e from the foot,
    /// ∇e = `gradient` (the unit vector from its closest point to the foot).
    pub(crate) fn add(&mut self, key: u32, normal: Vector3<f64>, distance: f64, gradient: Vector3<f64>) {
        let ratio = distance / self.depth;
        let (weight, slope) = smooth_step_down((ratio - 1.0) / INSIDE_BLEND_BAND);
        if weight == 0.0 {
            return;
        }
        // ∇w = φ'(u) ∇u, ∇u = (∇e - (e / e_min) ∇e_min) / (β e_min).
        let weight_gradient = slope / (INSIDE_BLEND_BAND * self.depth) * (gradient + ratio * self.closest.0);
        if let Some(entry) = self.normals[..self.len].iter_mut().find(|(_, n, _, _)| n.dot(&normal) > 1.0 - 1e-12) {
            if key < entry.0 {
                (entry.0, entry.1) = (key, normal);
            }
            if weight > entry.2 {
                (entry.2, entry.3) = (weight, weight_gradient);
            }
        } else if self.len < self.normals.len() {
            self.normals[self.len] = (key, normal, weight, weight_gradient);
            self.len += 1;
        } else {
            self.overflow.0 += weight * normal;
            self.overflow.1 += normal * weight_gradient.transpose();
        }
    }

    /// The unit normal n = s / |s|, s = f Σ w n_face + (1 - f) n_c with the fade f, and
    /// ∂n/∂p = (I - n nᵀ) (∂s/∂p) / |s|; n_c when the faces' normals cancel (opposite faces
    /// equally near: a wall thinner than twice the depth).
    pub(crate) fn normal(&mut self) -> (Vector3<f64>, Matrix3<f64>) {
        let normals = &mut self.normals[..self.len];
        normals.sort_unstable_by_key(|entry| entry.0);
        let (blend, blend_jacobian) = normals.iter().fold(self.overflow, |(s, ds), (_, n, w, dw)| (s + *w * n, ds + n * dw.transpose()));
        let ((n_c, dn_c), (fade, fade_slope)) = (self.closest, self.fade);
        // ∇f = f'(e_min) ∇e_min = -f' n_c.
        let sum = fade * blend + (1.0 - fade) * n_c;
        let sum_jacobian = fade * blend_jacobian + (1.0 - fade) * dn_c - fade_slope * (blend - n_c) * n_c.transpose();
        let norm = sum.norm();
        if norm > 1e-9 {
            let n = sum / norm;
            (n, (Matrix3::identity() - n * n.transpose()) * sum_jacobian / norm)
        } else {
            (n_c, dn_c)
        }
    }
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

    /// Whether there is ground below (x, y): everywhere on the analytic terrains and the
    /// heightfields (extended beyond their grid), within its footprint for a mesh.
    fn covers(&self, _x: f64, _y: f64) -> bool {
        true
    }
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
    Proximity { penetration: n.z * (h - p.z) + radius, normal: n, penetration_gradient: -n, penetration_hessian: Matrix3::zeros(), normal_jacobian: Matrix3::zeros() }
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
