//! Tip-over stability of the support on uneven ground (beyond the thesis: its conclusion names
//! the "integration of stability issues in the choice of the swinging leg in the free gait
//! algorithm ... tip-over stability should also be considered ... on uneven ground").
//!
//! The measure is the normalized energy stability margin (NESM) of S. Hirose, H. Tsukagoshi
//! and K. Yoneda, "Normalized energy stability margin and its contour of walking vehicles on
//! rough terrain", Proc. IEEE ICRA 2001, pp. 181-186: the smallest height the centre of mass
//! must rise by for the robot to tip over one edge of its support polygon, rotating about the
//! line through the two feet of that edge. Unlike the horizontal static margin (the distance of
//! the centre of mass' projection to the polygon's sides) it sees the feet's heights and the
//! height of the centre of mass: on a slope, the downhill edges have a smaller margin than the
//! uphill ones for the same horizontal distances.

use nalgebra::{Vector2, Vector3};

/// The support polygon: the vertices of the convex hull of the feet's horizontal projections,
/// counter-clockwise seen from above (z up), each with its foot's height (Andrew's monotone
/// chain; a handful of feet need no geometry library). Feet on the hull's sides between two
/// vertices are left out.
pub fn support_polygon(feet: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let mut points: Vec<Vector3<f64>> = feet.to_vec();
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup_by(|a, b| a.x == b.x && a.y == b.y);
    if points.len() < 3 {
        return points;
    }
    let turn = |o: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>| (a.xy() - o.xy()).perp(&(b.xy() - o.xy()));
    let mut hull: Vec<Vector3<f64>> = Vec::with_capacity(2 * points.len());
    for pass in [points.clone(), points.iter().rev().copied().collect()] {
        let start = hull.len();
        for p in pass {
            while hull.len() >= start + 2 && turn(&hull[hull.len() - 2], &hull[hull.len() - 1], &p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The normalized energy stability margin (m) of the centre of mass `com` over the support
/// feet `feet` (global frame, z up): the smallest, over the edges of the support polygon
/// ([`support_polygon`]), of the rise of the centre of mass when the robot rotates about the
/// edge until the centre of mass is over it. Negative when the centre of mass is already beyond
/// an edge (it then falls by rotating about it, by at least that much); −∞ with fewer than three
/// feet or feet on one line (no polygon).
///
/// For an edge from foot a to foot b (unit vector e), the centre of mass turns about the edge
/// on a circle of radius |r|, r = (c − a) − ((c − a)·e) e, centred at o = c − r. Its highest
/// point is where it is in the vertical plane of the edge, at the height o_z + |r| √(1 − e_z²),
/// so the edge's margin is h = o_z + |r| √(1 − e_z²) − c_z (Hirose et al., Eq. 5 with
/// |R|(1 − cos θ) cos ψ written in the edge's own terms), with the sign of the side of that
/// plane the centre of mass is on (+ towards the polygon).
pub fn energy_stability_margin(com: &Vector3<f64>, feet: &[Vector3<f64>]) -> f64 {
    let polygon = support_polygon(feet);
    if polygon.len() < 3 {
        return f64::NEG_INFINITY;
    }
    let n = polygon.len();
    (0..n).map(|i| edge_margin(com, &polygon[i], &polygon[(i + 1) % n])).fold(f64::INFINITY, f64::min)
}

/// The margin of one edge a → b of a counter-clockwise polygon (see [`energy_stability_margin`]).
fn edge_margin(c: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let e = (b - a).normalize();
    let r = (c - a) - e * (c - a).dot(&e);
    // o_z + |r| √(1 − e_z²) − c_z with o = c − r.
    let rise = r.norm() * (1.0 - e.z * e.z).max(0.0).sqrt() - r.z;
    let inside = Vector2::new(e.x, e.y).perp(&(c - a).xy());
    if inside >= 0.0 { rise } else { -rise }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute-force oracle: the centre of mass turned about the edge through a fine sweep of
    /// angles (Rodrigues' formula), its highest point less its height now.
    fn swept_rise(c: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
        let e = (b - a).normalize();
        let v = c - a;
        (0..=200_000)
            .map(|k| {
                let t = std::f64::consts::PI * (k as f64 / 100_000.0 - 1.0);
                let turned = v * t.cos() + e.cross(&v) * t.sin() + e * e.dot(&v) * (1.0 - t.cos());
                a.z + turned.z
            })
            .fold(f64::NEG_INFINITY, f64::max)
            - c.z
    }

    #[test]
    fn support_polygon_is_the_counter_clockwise_hull() {
        let p = |x: f64, y: f64| Vector3::new(x, y, 0.1 * x);
        // A foot inside and one on a side are not vertices.
        let hull = support_polygon(&[p(0.0, 0.0), p(1.0, 1.0), p(-1.0, 1.0), p(0.0, -1.0), p(0.0, 1.0), p(0.1, 0.2)]);
        assert_eq!(hull, vec![p(-1.0, 1.0), p(0.0, -1.0), p(1.0, 1.0)]);
    }

    /// Flat ground, an equilateral triangle of feet whose sides are d from the centre of mass'
    /// projection, the centre of mass H above them: every edge's rise is √(d² + H²) − H.
    #[test]
    fn flat_ground_triangle_by_hand() {
        let (d, height) = (0.12, 0.4);
        let r = 2.0 * d; // the circumradius of an equilateral triangle is twice its inradius
        let feet: Vec<Vector3<f64>> = (0..3).map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 3.0;
            Vector3::new(r * a.cos(), r * a.sin(), 0.0)
        }).collect();
        let com = Vector3::new(0.0, 0.0, height);
        let expected = (d * d + height * height).sqrt() - height;
        assert!((energy_stability_margin(&com, &feet) - expected).abs() < 1e-12);
        // Moved beyond the edge opposite the first foot (x = −d) by 5 mm: minus the rise back.
        let out = Vector3::new(-d - 0.005, 0.0, height);
        let back = (0.005f64.powi(2) + height * height).sqrt() - height;
        assert!((energy_stability_margin(&out, &feet) + back).abs() < 1e-12);
        assert_eq!(energy_stability_margin(&com, &feet[..2]), f64::NEG_INFINITY);
        let collinear = [Vector3::zeros(), Vector3::x(), Vector3::x() * 2.0];
        assert_eq!(energy_stability_margin(&com, &collinear), f64::NEG_INFINITY);
    }

    /// Ground tilted by α about x (the robot on a slope, across it), the edge along x downhill:
    /// the centre of mass, (0, w, H) from the edge in the ground's frame, is at the height
    /// w sin α + H cos α above it and rises to √(w² + H²).
    #[test]
    fn tilted_ground_downhill_edge_by_hand() {
        let (w, height, alpha) = (0.15, 0.3, 20f64.to_radians());
        let tilt = |p: Vector3<f64>| Vector3::new(p.x, p.y * alpha.cos() - p.z * alpha.sin(), p.y * alpha.sin() + p.z * alpha.cos());
        // Uphill to +y: the edge y = −w is the lower one.
        let feet = [tilt(Vector3::new(-0.3, -w, 0.0)), tilt(Vector3::new(0.3, -w, 0.0)), tilt(Vector3::new(0.0, 0.4, 0.0))];
        let com = tilt(Vector3::new(0.0, 0.0, height));
        let downhill = (w * w + height * height).sqrt() - (w * alpha.sin() + height * alpha.cos());
        assert!((edge_margin(&com, &feet[0], &feet[1]) - downhill).abs() < 1e-12);
        // The downhill edge is the weakest here, and smaller than on flat ground.
        let m = energy_stability_margin(&com, &feet);
        assert!((m - downhill).abs() < 1e-12);
        assert!(m < (w * w + height * height).sqrt() - height);
    }

    /// Random supports on uneven ground, inclined edges included: each edge's margin against the
    /// swept rotation.
    #[test]
    fn edge_margins_against_the_swept_rotation() {
        let mut seed = 7u64;
        let mut uniform = |lo: f64, hi: f64| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
        };
        for _ in 0..50 {
            let feet: Vec<Vector3<f64>> = (0..4).map(|_| Vector3::new(uniform(-0.4, 0.4), uniform(-0.4, 0.4), uniform(-0.1, 0.1))).collect();
            let com = Vector3::new(uniform(-0.1, 0.1), uniform(-0.1, 0.1), uniform(0.1, 0.5));
            let polygon = support_polygon(&feet);
            for i in 0..polygon.len() {
                let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
                let m = edge_margin(&com, &a, &b);
                assert!((m.abs() - swept_rise(&com, &a, &b)).abs() < 1e-8, "{m} against {}", swept_rise(&com, &a, &b));
            }
        }
    }
}
