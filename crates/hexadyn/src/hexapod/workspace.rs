//! The leg workspace (thesis Section 7.1.1, Fig. 7.3) and the kinematic margin of Section 7.7.3
//! (Eq. 7.3); the module docs of [`super::leg_kinematics`] say how the cylinder is built.

use nalgebra::{Vector2, Vector3};

use std::sync::Mutex;

use super::leg_kinematics::{JointLimits, LegKinematics, LegKinematicsError};
use super::pantograph::PantographGeometry;

/// Workspaces remembered by [`LegKinematics::workspace`] and
/// [`super::SerialLegKinematics::workspace`].
pub const RECENT_WORKSPACES: usize = 64;

/// The last [`RECENT_WORKSPACES`] workspace searches of a leg mechanism, by their key.
pub(crate) type Recent<K> = Mutex<Vec<(K, Result<Workspace, LegKinematicsError>)>>;

/// The workspace of `key` from `recent`, or `search`ed and remembered (the oldest forgotten).
pub(crate) fn remembered<K: PartialEq + Clone>(recent: &Recent<K>, key: K, search: impl FnOnce() -> Result<Workspace, LegKinematicsError>) -> Result<Workspace, LegKinematicsError> {
    if let Some((_, found)) = recent.lock().ok().and_then(|r| r.iter().find(|(k, _)| *k == key).cloned()) {
        return found;
    }
    let result = search();
    if let Ok(mut r) = recent.lock() {
        if r.len() >= RECENT_WORKSPACES {
            let _forgotten = r.remove(0);
        }
        r.push((key, result.clone()));
    }
    result
}

impl LegKinematics {

    /// (F_x, F_z) of the planar linkage along edge `k` of the (q_v, q_h) box, t in [0, 1].
    fn edge_foot(&self, k: usize, t: f64) -> Vector2<f64> {
        let (lo, hi) = (self.limits.lower, self.limits.upper);
        let (q_v, q_h) = match k {
            0 => (lo[1] + t * (hi[1] - lo[1]), lo[2]),
            1 => (lo[1] + t * (hi[1] - lo[1]), hi[2]),
            2 => (lo[1], lo[2] + t * (hi[2] - lo[2])),
            _ => (hi[1], lo[2] + t * (hi[2] - lo[2])),
        };
        self.pantograph.foot(q_v, q_h)
    }

    /// Lowest and highest foot heights in the leg frame over the joint ranges (m).
    pub fn height_range(&self) -> (f64, f64) {
        // The map (q_v, q_h) → F has an invertible Jacobian: the extremes of F_z lie on the
        // edges of the box.
        let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..4 {
            let fz = |t: f64| self.edge_foot(k, t).y;
            lowest = lowest.min(-maximize(&|t| -fz(t), 0.0, 1.0, 64));
            highest = highest.max(maximize(&fz, 0.0, 1.0, 64));
        }
        (self.crossing.z + lowest, self.crossing.z + highest)
    }

    /// Range of F_x on the slice F_z = ζ of the pantograph's reachable set (leg plane),
    /// from the crossings of the image of the box boundary with the line F_z = ζ.
    fn slice(&self, zeta: f64) -> Option<(f64, f64)> {
        const N: usize = 32;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..4 {
            let h = |t: f64| self.edge_foot(k, t).y - zeta;
            let mut t0 = 0.0;
            let mut h0 = h(t0);
            for i in 1..=N {
                let t1 = i as f64 / N as f64;
                let h1 = h(t1);
                let root = if h0 == 0.0 {
                    Some(t0)
                } else if h1 == 0.0 {
                    Some(t1)
                } else if (h0 < 0.0) != (h1 < 0.0) {
                    Some(bisect(&h, t0, t1, h0))
                } else {
                    None
                };
                if let Some(t) = root {
                    let x = self.edge_foot(k, t).x;
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
                (t0, h0) = (t1, h1);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// Distance from the q_r axis of a foot with planar abscissa F_x.
    fn axis_distance(&self, fx: f64) -> f64 {
        (self.crossing.x + fx).hypot(self.crossing.y)
    }

    /// Reachable radii [ρ_lo(z), ρ_hi(z)] from the q_r axis at height z (leg frame), if any.
    pub fn radii_at(&self, z: f64) -> Option<(f64, f64)> {
        let (lo, hi) = self.slice(z - self.crossing.z)?;
        (self.crossing.x + lo > 0.0).then(|| (self.axis_distance(lo), self.axis_distance(hi)))
    }

    /// The workspace cylinder for foot heights [z_min, z_max] (leg frame): the largest
    /// vertical cylinder reachable at every height of the range (see the module docs).
    ///
    /// The last [`RECENT_WORKSPACES`] results are kept (a campaign or a sweep validates the same
    /// walk many times; the search costs milliseconds).
    pub fn workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError> {
        static RECENT: Recent<(PantographGeometry, Vector3<f64>, JointLimits, u64, u64)> = Mutex::new(Vec::new());
        remembered(&RECENT, (self.pantograph, self.crossing, self.limits, z_min.to_bits(), z_max.to_bits()), || self.search_workspace(z_min, z_max))
    }

    fn search_workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError> {
        if !(z_min.is_finite() && z_max.is_finite()) {
            return Err(LegKinematicsError::NonFinite("workspace height range"));
        }
        let (lowest, highest) = self.height_range();
        if !(z_min <= z_max && z_min > lowest && z_max < highest) {
            return Err(LegKinematicsError::HeightOutOfReach { z_min, z_max, lowest, highest });
        }
        let empty = LegKinematicsError::EmptyWorkspace { z_min, z_max };
        let zc = self.crossing.z;
        // Inner radius R1 = max ρ_lo(z), outer R2 = min ρ_hi(z) over the height range.
        let fx_lo = |z: f64| self.slice(z - zc).map_or(f64::INFINITY, |s| s.0);
        let fx_hi = |z: f64| self.slice(z - zc).map_or(f64::NEG_INFINITY, |s| s.1);
        let (fx1, fx2) = if z_max > z_min {
            (maximize(&fx_lo, z_min, z_max, 200), -maximize(&|z| -fx_hi(z), z_min, z_max, 200))
        } else {
            (fx_lo(z_min), fx_hi(z_min))
        };
        if !(fx1.is_finite() && fx2.is_finite() && self.crossing.x + fx1 > 0.0 && fx1 < fx2) {
            return Err(empty);
        }
        let (r1, r2) = (self.axis_distance(fx1), self.axis_distance(fx2));
        // Azimuth of the foot: −q_r + β(ρ), β = asin(c_y / ρ) (zero when C* is in the
        // vertical plane of x_l, as for AMRU5); the sector common to all ρ in [R1, R2].
        let (b1, b2) = ((self.crossing.y / r1).asin(), (self.crossing.y / r2).asin());
        let from = -self.limits.upper[0] + b1.max(b2);
        let to = -self.limits.lower[0] + b1.min(b2);
        if !(to > from) {
            return Err(empty);
        }
        let (half, bisector) = ((to - from) / 2.0, (to + from) / 2.0);
        // Largest disc in the annular sector, centre at d on the bisector:
        // max_d min(d − R1, R2 − d, d sin θ) (for θ ≥ π/2 the sector's sides are never closer
        // than the axis).
        let sin = if half >= std::f64::consts::FRAC_PI_2 { 1.0 } else { half.sin() };
        let d = ((r1 + r2) / 2.0).max(r2 / (1.0 + sin));
        let radius = r2 - d;
        if !(radius > 0.0) {
            return Err(empty);
        }
        Ok(Workspace { centre: Vector2::new(d * bisector.cos(), d * bisector.sin()), radius, z_min, z_max })
    }

    /// The workspace for a level body at `height` above flat ground (the foot on the ground is
    /// at z = −height in the leg frame) and a foot lift `lift` (heights [−height, −height + lift]).
    pub fn workspace_for_body_height(&self, height: f64, lift: f64) -> Result<Workspace, LegKinematicsError> {
        self.workspace(-height, -height + lift)
    }

    /// True when `other` reaches the same points of its own leg frame: same pantograph, crossing
    /// C* and joint limits (the legs of AMRU5 differ only by their angle α on the body), so both
    /// have the same [`Workspace`] at every height.
    pub fn same_leg_frame_reach(&self, other: &LegKinematics) -> bool {
        self.pantograph == other.pantograph && self.crossing == other.crossing && self.limits == other.limits
    }
}

/// Root of h in [a, b] (sign change, h(a) = ha) by bisection to machine precision.
fn bisect(h: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, mut ha: f64) -> f64 {
    for _ in 0..80 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let hm = h(m);
        if hm == 0.0 {
            return m;
        }
        if (hm < 0.0) == (ha < 0.0) {
            (a, ha) = (m, hm);
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// max of f over [a, b]: the best of n + 1 samples, refined by golden-section search in the
/// bracket around it.
fn maximize(f: &dyn Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    argmax(f, a, b, n, 0.0).1
}

/// [`maximize`] with the argument: (x, f(x)) of the best value met. The golden-section search
/// stops when its bracket is narrower than `tolerance` (in x), or than the rounding of x.
pub(super) fn argmax(f: &dyn Fn(f64) -> f64, a: f64, b: f64, n: usize, tolerance: f64) -> (f64, f64) {
    let x = |i: usize| a + (b - a) * i as f64 / n as f64;
    let (mut i_best, mut best) = (0, f(a));
    let mut x_best = a;
    for i in 1..=n {
        let v = f(x(i));
        if v > best {
            (i_best, best, x_best) = (i, v, x(i));
        }
    }
    let (mut lo, mut hi) = (x(i_best.saturating_sub(1)), x((i_best + 1).min(n)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..200 {
        if hi - lo <= tolerance.max(4.0 * f64::EPSILON * (lo.abs() + hi.abs())) {
            break;
        }
        if fc >= fd {
            (hi, d, fd) = (d, c, fc);
            c = hi - g * (hi - lo);
            fc = f(c);
        } else {
            (lo, c, fc) = (c, d, fd);
            d = lo + g * (hi - lo);
            fd = f(d);
        }
    }
    let value = best.max(fc).max(fd);
    let at = [(x_best, best), (c, fc), (d, fd)].into_iter().find(|&(_, v)| v == value).map_or(x_best, |(x, _)| x);
    (at, value)
}

/// The workspace of a leg (Fig. 7.3): a vertical cylinder in the leg frame, of centre C =
/// (centre, z), radius `radius`, for heights [z_min, z_max].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Workspace {
    /// Horizontal position (x, y) of the axis of the cylinder, leg frame (m).
    pub centre: Vector2<f64>,
    pub radius: f64,
    pub z_min: f64,
    pub z_max: f64,
}

impl Workspace {
    /// The centre C at height z (leg frame): p_{C/l} of Eq. 7.24 and 7.30.
    pub fn centre_at(&self, z: f64) -> Vector3<f64> {
        Vector3::new(self.centre.x, self.centre.y, z)
    }

    /// True when p is inside the cylinder or less than `tolerance` outside.
    pub fn contains(&self, p: &Vector3<f64>, tolerance: f64) -> bool {
        self.distance_outside(p) <= tolerance
    }

    /// Euclidean distance from p to the solid cylinder (0 inside).
    pub fn distance_outside(&self, p: &Vector3<f64>) -> f64 {
        let radial = ((p.xy() - self.centre).norm() - self.radius).max(0.0);
        let vertical = (self.z_min - p.z).max(p.z - self.z_max).max(0.0);
        radial.hypot(vertical)
    }

    /// A cylinder `security` smaller on every side (the "constrained working volume" of
    /// Section 7.1.1, restricted for a degree of security on the joint limits).
    pub fn shrunk(&self, security: f64) -> Workspace {
        Workspace { radius: self.radius - security, z_min: self.z_min + security, z_max: self.z_max - security, ..*self }
    }

    /// The cylinder with its axis moved `offset` away from the leg's mount (towards it when
    /// negative) along the horizontal direction of its centre, its radius reduced by |offset|
    /// so that it stays inside this one; `None` when nothing is left (|offset| >= radius) or
    /// the centre is on the mount's vertical (no direction).
    pub fn moved_radially(&self, offset: f64) -> Option<Workspace> {
        let distance = self.centre.norm();
        let radius = self.radius - offset.abs();
        (radius > 0.0 && distance > 0.0).then(|| Workspace { centre: self.centre * ((distance + offset) / distance), radius, ..*self })
    }

    /// Kinematic margin (Section 7.7.3, [MCGH79, LEE88]): the distance the foot at p can still
    /// travel along `direction` (leg frame; the motion of the foot relative to the leg, i.e.
    /// opposite to the body's in support) before it leaves the cylinder. Zero on the boundary
    /// when moving outwards; infinite for a zero direction (inside); negative outside: minus
    /// the distance to the cylinder. Never NaN for finite inputs.
    pub fn margin(&self, p: &Vector3<f64>, direction: &Vector3<f64>) -> f64 {
        let outside = self.distance_outside(p);
        if outside > 0.0 {
            return -outside;
        }
        let norm = direction.norm();
        if !(norm > 0.0) || !norm.is_finite() {
            return f64::INFINITY;
        }
        let u = direction / norm;
        let mut t = f64::INFINITY;
        // Side: |d + t u_h| = R with d = p_h − C (largest root).
        let a = u.xy().norm_squared();
        if a > 0.0 {
            let d = p.xy() - self.centre;
            let b = d.dot(&u.xy());
            let c = (d.norm_squared() - self.radius * self.radius).min(0.0);
            let root = (b * b - a * c).max(0.0).sqrt();
            let side = if b > 0.0 { -c / (b + root) } else { (root - b) / a };
            t = t.min(side.max(0.0));
        }
        if u.z > 0.0 {
            t = t.min(((self.z_max - p.z) / u.z).max(0.0));
        } else if u.z < 0.0 {
            t = t.min(((self.z_min - p.z) / u.z).max(0.0));
        }
        t
    }

    /// Temporal kinematic margin t_S = d / v of Eq. 7.3 for a foot moving at `velocity`
    /// (leg frame, m/s): infinite when it does not move.
    pub fn temporal_margin(&self, p: &Vector3<f64>, velocity: &Vector3<f64>) -> f64 {
        let v = velocity.norm();
        if !(v > 0.0) {
            return f64::INFINITY;
        }
        self.margin(p, velocity) / v
    }
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::hexapod::leg_kinematics::tests::{amru5, neutral, neutral_workspace};
    use crate::test_util::rng;
    use rand::Rng;
    use approx::assert_relative_eq;

    /// A cylinder moved radially (`gait.foothold_offset_m`) lies inside the original and
    /// touches it on the side it moved to: its axis `offset` further from the mount along the
    /// centre's direction, its radius |offset| smaller; nothing is left at |offset| >= radius.
    #[test]
    fn moved_radially_stays_inside_and_touches() {
        let w = neutral_workspace(&amru5()[0]);
        for offset in [-0.03, -1e-3, 0.0, 1e-3, 0.03, 0.9 * w.radius] {
            let m = w.moved_radially(offset).unwrap();
            assert_relative_eq!(m.centre.norm(), w.centre.norm() + offset, epsilon = 1e-15);
            assert_relative_eq!(m.centre.normalize(), w.centre.normalize(), epsilon = 1e-15);
            assert_eq!((m.radius, m.z_min, m.z_max), (w.radius - offset.abs(), w.z_min, w.z_max));
            let mut widest: f64 = 0.0;
            for ia in 0..3600 {
                let a = (ia as f64 / 10.0).to_radians();
                let p = m.centre_at(w.z_min) + Vector3::new(a.cos(), a.sin(), 0.0) * m.radius;
                assert!(w.contains(&p, 1e-12), "offset {offset}: {p} outside");
                widest = widest.max((p.xy() - w.centre).norm());
            }
            assert_relative_eq!(widest, w.radius, epsilon = 1e-9);
        }
        assert_eq!(w.moved_radially(0.0).unwrap(), w);
        assert!(w.moved_radially(w.radius).is_none() && w.moved_radially(-w.radius).is_none());
        assert!(Workspace { centre: Vector2::zeros(), ..w }.moved_radially(0.01).is_none());
    }

    /// The workspace cylinder is reachable everywhere on its boundary (IK unclamped), the
    /// kinematic margin is zero there, and it is the largest: 0.1 mm wider is not reachable.
    #[test]
    fn leg_kinematics_workspace_is_reachable_and_maximal() {
        let legs = amru5();
        let (lowest, highest) = legs[0].height_range();
        let w = neutral_workspace(&legs[0]);
        let full = legs[0].workspace(lowest + 1e-3, highest - 1e-3).unwrap();
        println!("reachable foot heights (leg frame): [{lowest:.6}, {highest:.6}] m");
        for z in [w.z_min, w.z_max, lowest + 1e-3, highest - 1e-3] {
            println!("reachable radii from the q_r axis at z = {z:.4}: {:?}", legs[0].radii_at(z));
        }
        for (name, w) in [("neutral height, 5 cm lift", w), ("all heights", full)] {
            println!(
                "workspace ({name}): centre ({:.6}, {:.6}) m in the leg frame, {:.6} m from the body centre, radius {:.6} m, z [{:.6}, {:.6}] m",
                w.centre.x,
                w.centre.y,
                w.centre.x + 0.175,
                w.radius,
                w.z_min,
                w.z_max
            );
        }
        let mut longer_stroke = legs[0].clone();
        longer_stroke.limits.upper[1] += 0.01;
        assert!(!longer_stroke.same_leg_frame_reach(&legs[0]));
        for kin in &legs {
            // The legs differ only by their place on the body: the scenarios share one search.
            assert!(kin.same_leg_frame_reach(&legs[0]));
            assert_eq!(kin.workspace(w.z_min, w.z_max).unwrap(), w);
            let bigger = Workspace { radius: w.radius + 1e-4, ..w };
            let mut clamped = 0;
            for iz in 0..=6 {
                let z = w.z_min + (w.z_max - w.z_min) * iz as f64 / 6.0;
                for ia in 0..360 {
                    let a = (ia as f64).to_radians();
                    let u = Vector3::new(a.cos(), a.sin(), 0.0);
                    let p = w.centre_at(z) + u * w.radius;
                    let s = kin.inverse(&p, &neutral()).unwrap();
                    assert!(s.is_reached(), "boundary point {p}: {s:?}");
                    assert!(s.iterations <= 8);
                    assert!(w.margin(&p, &u).abs() <= 1e-12, "margin {}", w.margin(&p, &u));
                    assert_relative_eq!(w.margin(&w.centre_at(z), &u), w.radius, epsilon = 1e-12);
                    if !kin.inverse(&(bigger.centre_at(z) + u * bigger.radius), &neutral()).unwrap().is_reached() {
                        clamped += 1;
                    }
                    // Top and bottom discs.
                    let inner = w.centre_at(if ia % 2 == 0 { w.z_min } else { w.z_max }) + u * (w.radius * (ia % 7) as f64 / 7.0);
                    assert!(kin.inverse(&inner, &neutral()).unwrap().is_reached());
                }
            }
            assert!(clamped > 0, "a cylinder 0.1 mm wider is reachable too: not the largest");
            // Body frame: the centre of leg i turns with α.
            let c = kin.to_body(&w.centre_at(w.z_min));
            assert_relative_eq!(c.y.atan2(c.x), kin.alpha(), epsilon = 1e-12);
        }
        // AMRU5's q_r range is symmetric and C* lies in the plane x_l z_l: C on the x_l axis.
        assert!(w.centre.y.abs() < 1e-15 && w.radius > 0.1);
        // Heights beyond the reachable ones are refused.
        assert!(legs[0].workspace(lowest - 0.01, -0.4).is_err());
        assert!(legs[0].workspace(-0.4, highest + 0.01).is_err());
        assert!(legs[0].workspace(-0.3, -0.4).is_err());
    }

    /// The kinematic margin (Section 7.7.3) along a direction: the point it leads to is on
    /// the boundary, and it is consistent with the temporal margin of Eq. 7.3.
    #[test]
    fn leg_kinematics_kinematic_margin() {
        let legs = amru5();
        let w = neutral_workspace(&legs[0]);
        let mut r = rng(9);
        for _ in 0..2000 {
            let (rho, phi) = (w.radius * r.random_range(0.0f64..=1.0).sqrt(), r.random_range(0.0..std::f64::consts::TAU));
            let p = Vector3::new(w.centre.x + rho * phi.cos(), w.centre.y + rho * phi.sin(), r.random_range(w.z_min..=w.z_max));
            let v = Vector3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), if r.random_bool(0.5) { 0.0 } else { r.random_range(-0.2..0.2) });
            let m = w.margin(&p, &v);
            assert!(m.is_finite() && m >= 0.0);
            let end = p + v.normalize() * m;
            let on_side = ((end.xy() - w.centre).norm() - w.radius).abs() <= 1e-12;
            let on_cap = (end.z - w.z_min).abs() <= 1e-12 || (end.z - w.z_max).abs() <= 1e-12;
            assert!(on_side || on_cap, "{end}");
            assert!(w.contains(&end, 1e-12) && !w.contains(&(p + v.normalize() * (m + 1e-6)), 0.0));
            assert_relative_eq!(w.temporal_margin(&p, &(v * 0.02)), m / (v.norm() * 0.02), max_relative = 1e-12);
        }
        // Outside: minus the distance; no motion: infinite.
        let out = w.centre_at(w.z_min) + Vector3::new(w.radius + 0.01, 0.0, 0.0);
        assert_relative_eq!(w.margin(&out, &Vector3::x()), -0.01, epsilon = 1e-12);
        assert_eq!(w.margin(&w.centre_at(w.z_min), &Vector3::zeros()), f64::INFINITY);
        // Shrinking gives the security margin on every side.
        let s = w.shrunk(0.01);
        assert_relative_eq!(s.margin(&s.centre_at(s.z_min), &Vector3::x()), w.radius - 0.01, epsilon = 1e-12);
    }
}
