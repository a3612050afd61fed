//! An analytic step: two horizontal half planes joined by a vertical face.

use nalgebra::{Vector2, Vector3};

use super::{Extent, Proximity, Terrain, Triangles};

/// The ground at z = `base` on the low side of a straight edge and z = `base` + `rise` on the
/// high side, joined by a vertical face. The edge is the line u · (x, y) = `edge`, u the
/// horizontal unit vector at `azimuth` (rad from x_0 about z_0), pointing to the high side.
///
/// Edge treatment (closest point, as every [`Terrain`]): in the vertical plane across the edge
/// the surface is the polyline low half line, vertical face, high half line. A foot above the
/// top corner is pushed away from the corner (the normal turns continuously from vertical to
/// horizontal over the corner's Voronoi region: the corner acts as a rounded edge of zero
/// radius); a foot that penetrated is pushed out through the nearest face, so a point foot that
/// sinks into the top face near the corner is pushed up while it is closer to the top face and
/// sideways once it is closer to the vertical face. That switch, on the corner's bisector, and
/// the same one in the concave corner at the foot of the face (a foot touching both faces feels
/// only the nearer one) are real discontinuities of the contact normal: a sharp edge has no
/// unique normal.
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

    /// Profile coordinates of p: s across the edge (> 0 on the high side), w above the base.
    fn profile(&self, p: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(self.u().dot(p) - self.edge, p.z - self.base)
    }

    /// Closest point of the profile to `q` and its feature.
    fn closest(&self, q: &Vector2<f64>) -> (Vector2<f64>, Feature) {
        let up = Vector2::new(0.0, 1.0);
        let bisector = Vector2::new(-1.0, 1.0).normalize();
        let h = self.rise;
        let candidates = [
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
        ];
        candidates.into_iter().min_by(|a, b| (q - a.0).norm_squared().total_cmp(&(q - b.0).norm_squared())).expect("three candidates")
    }
}

impl Terrain for Step {
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>) {
        let s = self.profile(&Vector3::new(x, y, 0.0)).x;
        (if s >= 0.0 { self.base + self.rise } else { self.base }, Vector3::z())
    }

    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        let q = self.profile(p);
        let (c, feature) = self.closest(&q);
        let inside = q.y < 0.0 || (q.x > 0.0 && q.y < self.rise);
        let (distance, n) = match feature {
            Feature::Face(n) => (n.dot(&(q - c)), n),
            Feature::Corner(bisector) => {
                let d = (q - c).norm();
                if d > 0.0 {
                    let sign = if inside { -1.0 } else { 1.0 };
                    (sign * d, sign * (q - c) / d)
                } else {
                    (0.0, bisector)
                }
            }
        };
        Proximity { penetration: radius - distance, normal: n.x * self.u() + n.y * Vector3::z() }
    }

    /// A square of the extent's size aligned with the edge: the low part, the face and the high
    /// part where the edge crosses it.
    fn triangles(&self, extent: Extent) -> Triangles {
        let u = self.u();
        let t = Vector3::new(-u.y, u.x, 0.0);
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
