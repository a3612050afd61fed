//! Footholds for five legs (beyond the thesis): with a leg failed at the trailing end of the
//! walk, the feet of the legs beside the body centre keep behind it, so that the lone leg left
//! at that end can always lift.
//!
//! With a rear leg failed (walking forwards), the other rear foot is the only one behind the
//! body centre: when it lifts, the support polygon of the four others has for its rear edge the
//! line between the two middle feet. The middle legs land at the AEP of maximum margin, ahead
//! of the body centre; the rear leg reached its rear boundary while they were still ahead, its
//! lift would have tipped the robot, and no body sway that keeps the rear foot in its workspace
//! brought the centre inside the four other feet: the walk halted for good after 0.28 m
//! (issue 37, legs 4 and 5 failed; legs 0 and 1 walking backwards). Fault-tolerant gaits
//! keep a hexapod with a failed leg statically stable on the legs left (J.-M. Yang and J.-H.
//! Kim, "Fault-tolerant locomotion of the hexapod robot", IEEE Trans. SMC-B 28(1), 1998), as
//! the crawl gaits of quadrupeds keep the centre of mass inside the support of the feet left
//! when a leg lifts (R. B. McGhee and A. A. Frank, "On the
//! stability properties of quadruped creeping gaits", Math. Biosci. 3, 1968). Here each middle
//! foot keeps to a half-plane of the body frame ([`Band`]) behind the line through the body
//! centre across the walk: the rear edge of the lone leg's support polygon stays behind the
//! centre whatever the phases of the other legs, and the lone leg lifts when Rule 3 asks (its
//! neighbours, the two middle legs, in support: Rule 2).
//!
//! INTERPRETATION: a leg failed at the leading end (a front leg, walking forwards) gets no band.
//! The lone front leg needs the middle feet ahead of the centre, where their AEP puts them after
//! each step; keeping them ahead for the whole support shortened their stroke to a third, and
//! on the ideal plant the walks with leg 0 or 1 failed covered 1.26 m of 1.5 m (against the
//! whole 1.5 m without).

use nalgebra::Vector3;

/// A half-plane of the body frame, {p : p · normal ≥ limit}, that a support foot keeps to
/// (`normal` horizontal and of unit length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    pub normal: Vector3<f64>,
    pub limit: f64,
}

impl Band {
    /// How far `p` (body frame) is inside the band (negative outside).
    pub fn depth(&self, p: &Vector3<f64>) -> f64 {
        p.dot(&self.normal) - self.limit
    }

    /// The distance a foot at `p` (body frame) moving along the unit direction `motion` (body
    /// frame) travels before it leaves the band: ∞ when it moves along the band or into it,
    /// negative (minus its distance to it) when it is outside.
    pub fn margin(&self, p: &Vector3<f64>, motion: &Vector3<f64>) -> f64 {
        let inside = self.depth(p);
        let rate = motion.dot(&self.normal);
        if inside < 0.0 {
            inside
        } else if rate < 0.0 {
            inside / -rate
        } else {
            f64::INFINITY
        }
    }

    /// How far `p` (body frame) must move along the normal to be `room` inside the band (0 if it
    /// is already).
    pub fn shortfall(&self, p: &Vector3<f64>, room: f64) -> f64 {
        (room - self.depth(p)).max(0.0)
    }
}

/// The bands of the working legs for a walk along `walking` (body frame, horizontal) with leg
/// `failed` held up: `centres` are the workspace centres (body frame) and `radii` the workspace
/// radii of the six legs, `limit` how far beyond the body centre the feet keep (m).
///
/// The failed leg is at the trailing end of the walk when its workspace lies wholly behind the
/// line through the body centre across the walk (c_f · û ≤ −R_f); the legs whose workspaces
/// straddle that line (|c_l · û| < R_l: the middle legs on a straight walk) then keep their
/// feet behind it, `limit` beyond it. No band otherwise: a leg failed at the leading end or in
/// the middle, a walk across the body, no walking motion (the lateral offset of the footholds,
/// `foothold_offsets` of the controller, serves there).
pub fn bands(failed: usize, walking: &Vector3<f64>, centres: &[Vector3<f64>; 6], radii: &[f64; 6], limit: f64) -> [Option<Band>; 6] {
    let horizontal = Vector3::new(walking.x, walking.y, 0.0);
    let speed = horizontal.norm();
    if !(speed > 0.0) {
        return [None; 6];
    }
    let u = horizontal / speed;
    let along = |l: usize| centres[l].dot(&u);
    if along(failed) > -radii[failed] {
        return [None; 6];
    }
    let normal = -u;
    std::array::from_fn(|l| (l != failed && along(l).abs() < radii[l]).then_some(Band { normal, limit }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// AMRU5's workspace centres (body frame, at the well-conditioned height): on a circle of
    /// 0.525 m at ±30°, ±90°, ±150°, radius 0.148 m.
    fn amru5() -> ([Vector3<f64>; 6], [f64; 6]) {
        let at = |deg: f64| Vector3::new(0.525 * deg.to_radians().cos(), 0.525 * deg.to_radians().sin(), -0.414);
        ([at(30.0), at(-30.0), at(90.0), at(-90.0), at(150.0), at(-150.0)], [0.148; 6])
    }

    /// A rear leg failed walking forwards, or a front leg walking backwards: the middle feet keep
    /// behind the body centre (in the walk's terms); a front leg failed walking forwards, a
    /// middle leg failed, a walk sideways, no walk: no band.
    #[test]
    fn the_middle_feet_keep_to_the_failed_legs_side() {
        let (c, r) = amru5();
        let forward = Vector3::new(0.005, 0.0, 0.0);
        for (failed, walking) in [(4, forward), (5, forward), (0, -forward), (1, -forward)] {
            let b = bands(failed, &walking, &c, &r, 0.03);
            let behind = Band { normal: -walking.normalize(), limit: 0.03 };
            assert_eq!(b, [None, None, Some(behind), Some(behind), None, None], "leg {failed}");
        }
        assert_eq!(bands(1, &forward, &c, &r, 0.03), [None; 6]);
        assert_eq!(bands(4, &-forward, &c, &r, 0.03), [None; 6]);
        assert_eq!(bands(3, &forward, &c, &r, 0.03), [None; 6]);
        assert_eq!(bands(0, &Vector3::new(0.0, 0.005, 0.0), &c, &r, 0.03), [None; 6]);
        assert_eq!(bands(4, &Vector3::zeros(), &c, &r, 0.03), [None; 6]);
    }

    /// The margin along the motion: to the band's edge when the foot moves towards it, infinite
    /// when it moves away, negative outside.
    #[test]
    fn margin_and_shortfall_by_hand() {
        let band = Band { normal: Vector3::x(), limit: 0.03 };
        let p = Vector3::new(0.1, 0.5, -0.4);
        let back = -Vector3::x();
        assert!((band.margin(&p, &back) - 0.07).abs() < 1e-12);
        let slanted = Vector3::new(-0.6, 0.8, 0.0);
        assert!((band.margin(&p, &slanted) - 0.07 / 0.6).abs() < 1e-12);
        assert_eq!(band.margin(&p, &Vector3::x()), f64::INFINITY);
        assert!((band.margin(&Vector3::new(0.01, 0.0, 0.0), &back) + 0.02).abs() < 1e-12);
        assert!((band.depth(&p) - 0.07).abs() < 1e-12 && band.depth(&Vector3::zeros()) == -0.03);
        assert_eq!(band.shortfall(&p, 0.01), 0.0);
        assert!((band.shortfall(&Vector3::new(0.0, 0.3, 0.0), 0.01) - 0.04).abs() < 1e-12);
    }
}
