//! An analytic step: two horizontal half planes joined by a vertical face.

use nalgebra::{Matrix3, Vector2, Vector3};

use super::{feature_normal_jacobian, Extent, InsideNormal, Proximity, Terrain, Triangles};

/// The ground at z = `base` on the low side of a straight edge and z = `base` + `rise` on the
/// high side, joined by a vertical face. The edge is the line u · (x, y) = `edge`, u the
/// horizontal unit vector at `azimuth` (rad from x_0 about z_0), pointing to the high side.
///
/// Edge treatment (closest point, as every [`Terrain`]): in the vertical plane across the edge
/// the surface is the polyline low half line, vertical face, high half line. A foot above the
/// top corner is pushed away from the corner (the normal turns continuously from vertical to
/// horizontal over the corner's Voronoi region: the corner acts as a rounded edge of zero
/// radius). Inside the ground the normal is the blend of the three faces' normals by their
/// distances ([`InsideNormal`]): a point foot sunk into the top face near the corner is pushed
/// up while the vertical face is more than twice as far as the top, then more and more sideways,
/// along the corner's bisector where both are as far, and sideways only once the top is twice as
/// far as the face. In front of the face, a foot sphere touching both the face and the low
/// ground feels only the nearer (the concave corner's discontinuity above the ground, which a
/// point foot never meets).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Height of the low side (m).
    pub base: f64,
    /// Height of the face, > 0 (m).
    pub rise: f64,
    /// Position of the edge along u (m).
    pub edge: f64,
    /// Direction u of the high side (rad).
    pub azimuth: f64,
}

/// The closest feature of the step's profile.
enum Feature {
    /// A face with its outward unit normal in the profile plane (s, w).
    Face(Vector2<f64>),
    /// A corner, with the bisector of its faces' normals.
    Corner(Vector2<f64>),
}

impl Step {
    fn u(&self) -> Vector3<f64> {
        Vector3::new(self.azimuth.cos(), self.azimuth.sin(), 0.0)
    }

    /// The horizontal unit vector along the edge, u turned a quarter turn about z_0.
    fn along(&self) -> Vector3<f64> {
        let u = self.u();
        Vector3::new(-u.y, u.x, 0.0)
    }

    /// Profile coordinates of p: s across the edge (> 0 on the high side), w above the base.
    fn profile(&self, p: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(self.u().dot(p) - self.edge, p.z - self.base)
    }

    /// The closest point of each part of the profile to `q` (low half line, vertical face, high
    /// half line) and its feature.
    fn candidates(&self, q: &Vector2<f64>) -> [(Vector2<f64>, Feature); 3] {
        let up = Vector2::new(0.0, 1.0);
        let bisector = Vector2::new(-1.0, 1.0).normalize();
        let h = self.rise;
        [
            // Low half line, s <= 0, w = 0.
            if q.x < 0.0 { (Vector2::new(q.x, 0.0), Feature::Face(up)) } else { (Vector2::zeros(), Feature::Corner(bisector)) },
            // Vertical face, s = 0, 0 <= w <= H.
            if q.y <= 0.0 {
                (Vector2::zeros(), Feature::Corner(bisector))
            } else if q.y >= h {
                (Vector2::new(0.0, h), Feature::Corner(bisector))
            } else {
                (Vector2::new(0.0, q.y), Feature::Face(Vector2::new(-1.0, 0.0)))
            },
            // High half line, s >= 0, w = H.
            if q.x > 0.0 { (Vector2::new(q.x, h), Feature::Face(up)) } else { (Vector2::new(0.0, h), Feature::Corner(bisector)) },
        ]
    }
}

impl Terrain for Step {
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>) {
        let s = self.profile(&Vector3::new(x, y, 0.0)).x;
        (if s >= 0.0 { self.base + self.rise } else { self.base }, Vector3::z())
    }

    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        let q = self.profile(p);
        let candidates = self.candidates(&q);
        let (c, feature) = candidates.iter().min_by(|a, b| (q - a.0).norm_squared().total_cmp(&(q - b.0).norm_squared())).expect("three candidates");
        let inside = q.y < 0.0 || (q.x > 0.0 && q.y < self.rise);
        let to_space = |n: Vector2<f64>| n.x * self.u() + n.y * Vector3::z();
        let (distance, closest, curvature) = match feature {
            Feature::Face(n) => (n.dot(&(q - c)), to_space(*n), Matrix3::zeros()),
            Feature::Corner(bisector) => {
                let d = (q - c).norm();
                if d > 0.0 {
                    let sign = if inside { -1.0 } else { 1.0 };
                    let n = to_space(sign * (q - c) / d);
                    (sign * d, n, feature_normal_jacobian(n, Some(self.along()), sign * d))
                } else {
                    (0.0, to_space(*bisector), Matrix3::zeros())
                }
            }
        };
        let (normal, normal_jacobian) = if distance < 0.0 {
            let mut blend = InsideNormal::new(-distance, closest, curvature);
            if blend.reach().is_some() {
                for (part, (point, _)) in candidates.iter().enumerate() {
                    let face_normal = if part == 1 { Vector2::new(-1.0, 0.0) } else { Vector2::new(0.0, 1.0) };
                    let e = (q - point).norm();
                    blend.add(part as u32, to_space(face_normal), e, to_space((q - point) / e));
                }
            }
            blend.normal()
        } else {
            (closest, curvature)
        };
        Proximity { penetration: radius - distance, normal, penetration_gradient: -closest, penetration_hessian: -curvature, normal_jacobian }
    }

    /// A square of the extent's size aligned with the edge: the low part, the face and the high
    /// part where the edge crosses it.
    fn triangles(&self, extent: Extent) -> Triangles {
        let (u, t) = (self.u(), self.along());
        let centre = Vector3::new(extent.centre[0], extent.centre[1], 0.0);
        let (sc, tc, w) = (u.dot(&centre) - self.edge, t.dot(&centre), extent.half_width);
        let point = |s: f64, along: f64, z: f64| {
            let v = (s + self.edge) * u + along * t;
            [v.x, v.y, z]
        };
        let (lo, hi) = (self.base, self.base + self.rise);
        let (t0, t1) = (tc - w, tc + w);
        let quad = |out: &mut Triangles, corners: [[f64; 3]; 4]| {
            let first = out.vertices.len() as u32;
            out.vertices.extend(corners);
            out.faces.extend([[first, first + 1, first + 2], [first, first + 2, first + 3]]);
        };
        let mut out = Triangles::default();
        if sc + w <= 0.0 || sc - w >= 0.0 {
            let z = if sc - w >= 0.0 { hi } else { lo };
            quad(&mut out, [point(sc - w, t0, z), point(sc + w, t0, z), point(sc + w, t1, z), point(sc - w, t1, z)]);
            return out;
        }
        // Shared vertices along the edge: 0, 1 at the foot of the face, 2, 3 at its top.
        out.vertices.extend([point(0.0, t0, lo), point(0.0, t1, lo), point(0.0, t0, hi), point(0.0, t1, hi)]);
        out.vertices.extend([point(sc - w, t0, lo), point(sc - w, t1, lo), point(sc + w, t0, hi), point(sc + w, t1, hi)]);
        // (s, t, z) is right-handed with (u, t, z): counter-clockwise from above is s then t.
        out.faces.extend([[4, 0, 1], [4, 1, 5], [2, 6, 7], [2, 7, 3], [0, 2, 3], [0, 3, 1]]);
        out
    }
}
