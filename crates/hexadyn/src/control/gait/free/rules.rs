//! Selection of the swing candidates (thesis Section 7.7.3, Fig. 7.27): Rule 2 (a leg can swing
//! if and only if its neighbours are in support) and Rule 3 (lift the leg whose kinematic margin
//! is lower than its two neighbours'), the deadlock condition of Section 7.7.4, and their
//! extension to a robot with a failed leg.

use nalgebra::Vector2;

/// The clockwise circuit of the legs whose consecutive entries are neighbours (Fig. 7.27 is
/// lost; NOTES.md: 0-1-3-5-4-2-0, the neighbours of leg 1 are 0 and 3, of leg 4 are 2 and 5).
pub const CIRCUIT: [usize; 6] = [0, 1, 3, 5, 4, 2];

/// The neighbours (n₊, n₋) of each working leg, `None` for a failed one.
///
/// Beyond the thesis: a failed leg (held up) is never in support, so under Rule 2 its two
/// neighbours could never swing again. The rules extend to five legs by taking the circuit of
/// the working legs: the neighbours of a failed leg become each other's neighbours.
pub fn neighbours(failed: Option<usize>) -> [Option<(usize, usize)>; 6] {
    let circuit: Vec<usize> = CIRCUIT.iter().copied().filter(|&l| Some(l) != failed).collect();
    let n = circuit.len();
    let mut table = [None; 6];
    for (i, &l) in circuit.iter().enumerate() {
        table[l] = Some((circuit[(i + 1) % n], circuit[(i + n - 1) % n]));
    }
    table
}

/// The legs that start their swing now: those in support whose neighbours are in support
/// (Rule 2) and whose kinematic margin along the heading is lower than both neighbours' (Rule 3).
/// `support[l]`: leg l is in its support phase; `margin[l]`: its kinematic margin (m) along the
/// foot's motion in the leg frame. Two neighbours are never both candidates.
///
/// INTERPRETATION: equal margins (feet placed symmetrically, e.g. all at their workspace centres
/// at the start of a straight walk) would leave no leg "lower than its two neighbours" and the
/// robot deadlocked once they all reach their boundaries together; ties are broken by the leg
/// number (the lower number is the lower margin). A leg whose foot does not move (infinite
/// margin: the robot stands still) never lifts.
pub fn swing_candidates(support: &[bool; 6], margin: &[f64; 6], neighbours: &[Option<(usize, usize)>; 6]) -> [bool; 6] {
    let lower = |l: usize, n: usize| margin[l] < margin[n] || (margin[l] == margin[n] && l < n);
    std::array::from_fn(|l| match neighbours[l] {
        Some((a, b)) => support[l] && support[a] && support[b] && margin[l].is_finite() && lower(l, a) && lower(l, b),
        None => false,
    })
}

/// Section 7.7.4: the robot is deadlocked when a leg in support has reached the boundary of its
/// workspace (its margin is below `boundary`, the distance its foot moves in one control
/// period) and cannot be lifted (`lifting[l]` false).
pub fn deadlocked(support: &[bool; 6], margin: &[f64; 6], lifting: &[bool; 6], boundary: f64) -> bool {
    (0..6).any(|l| support[l] && !lifting[l] && margin[l] < boundary)
}

/// Static stability margin (m) of a horizontal point `c` over the support feet `feet` (their
/// horizontal positions): the largest, over the triangles of three feet, of the smallest signed
/// distance from `c` to the triangle's sides (positive inside). Negative when `c` is outside the
/// support polygon; −∞ for fewer than three feet.
pub fn stability_margin(c: &Vector2<f64>, feet: &[Vector2<f64>]) -> f64 {
    let mut best = f64::NEG_INFINITY;
    let n = feet.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                best = best.max(triangle_margin(c, &[feet[i], feet[j], feet[k]]));
            }
        }
    }
    best
}

fn triangle_margin(c: &Vector2<f64>, t: &[Vector2<f64>; 3]) -> f64 {
    let orientation = (t[1] - t[0]).perp(&(t[2] - t[0])).signum();
    if orientation == 0.0 {
        return f64::NEG_INFINITY;
    }
    (0..3)
        .map(|e| {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let edge = b - a;
            orientation * edge.perp(&(c - a)) / edge.norm()
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbour_table_of_fig_7_27() {
        let t = neighbours(None);
        assert_eq!(t[1], Some((3, 0)));
        assert_eq!(t[4], Some((2, 5)));
        for l in 0..6 {
            let (a, b) = t[l].unwrap();
            // Symmetric, and the two tripods {0, 3, 4}, {1, 2, 5} are independent sets.
            assert!(t[a].unwrap().1 == l && t[b].unwrap().0 == l);
            assert!([0, 3, 4].contains(&l) != [0, 3, 4].contains(&a));
        }
        let five = neighbours(Some(5));
        assert_eq!(five[5], None);
        assert_eq!(five[3], Some((4, 1)));
        assert_eq!(five[4], Some((2, 3)));
    }

    /// Rule 2 forbids neighbours together; Rule 3 picks local minima of the margin.
    #[test]
    fn rules_2_and_3() {
        let t = neighbours(None);
        let all = [true; 6];
        let margin = [0.01, 0.05, 0.06, 0.02, 0.03, 0.04];
        // Local minima along 0-1-3-5-4-2: leg 0 (0.01 < 0.05, 0.06), leg 3 (0.02 < 0.05, 0.04),
        // leg 4 (0.03 < 0.04, 0.06).
        assert_eq!(swing_candidates(&all, &margin, &t), [true, false, false, true, true, false]);
        // Leg 1 in the air: its neighbours 0 and 3 cannot swing (Rule 2).
        let mut support = all;
        support[1] = false;
        assert_eq!(swing_candidates(&support, &margin, &t), [false, false, false, false, true, false]);
        // Leg 0 at its boundary and not lifting: deadlock.
        let lifting = swing_candidates(&support, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &t);
        assert!(deadlocked(&support, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &lifting, 1e-4));
        assert!(!deadlocked(&all, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &swing_candidates(&all, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &t), 1e-4));
    }

    #[test]
    fn stability_margin_of_a_triangle() {
        let h = 3f64.sqrt() / 2.0;
        let feet = [Vector2::new(1.0, 0.0), Vector2::new(-0.5, h), Vector2::new(-0.5, -h)];
        assert!((stability_margin(&Vector2::zeros(), &feet) - 0.5).abs() < 1e-12);
        assert!((stability_margin(&Vector2::new(-0.7, 0.0), &feet) + 0.2).abs() < 1e-12);
        assert_eq!(stability_margin(&Vector2::zeros(), &feet[..2]), f64::NEG_INFINITY);
    }
}
