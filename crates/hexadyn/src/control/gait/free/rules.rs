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

/// Rule 2: leg `l` may swing only if it is a working leg in support and so are its two
/// neighbours.
pub fn rule_2(l: usize, support: &[bool; 6], neighbours: &[Option<(usize, usize)>; 6]) -> bool {
    support[l] && neighbours[l].is_some_and(|(a, b)| support[a] && support[b])
}

/// The legs that start their swing now (Rules 2 and 3 with the priority of [PORT04]).
/// `support[l]`: leg l is in its support phase; `margin[l]`: its kinematic margin (m) along the
/// foot's motion in the leg frame; `reserve` (m): the distance a foot travels in support while a
/// neighbour makes one step (takeoff, swing, landing). Two neighbours never lift together.
///
/// - Rule 2: a leg can swing if and only if its neighbours are in support.
/// - Rule 3, the priority: the leg with the lowest margin among those that Rule 2 allows swings
///   ("lift up the leg if its kinematic margin is lower than the one of its two neighbors"),
///   and so does every leg whose margin is below `reserve` (it cannot wait for a neighbour's
///   step) unless a neighbour with a lower margin swings.
/// - With them, every other leg that Rule 2 still allows swings too: the largest set of
///   non-neighbouring legs, and among sets of that size the one of lowest margins.
/// - A leg never swings ahead of a neighbour in support with a lower margin that Rule 2 holds
///   back (one of that neighbour's own neighbours is in the air).
///
/// INTERPRETATION: the thesis states that Rules 2 and 3 converge "to a tripod gait on flat
/// ground in most of the cases, and sometimes to a forward wave gait", and that [PORT04] reaches
/// the tripod "with rule 2 and some priority assignments on neighboring legs"; the figure with
/// the table is lost and PORT04's rules are not reproduced. Read as a priority among neighbours
/// by the margin alone (Rule 3 literally, or only among the legs that satisfy Rule 2), the wave
/// that lifts the circuit's opposite pairs {0, 5}, {2, 3}, {1, 4} in turn is a fixed point:
/// when a pair lands, each leg of the pair that landed first has the lowest margin of its
/// neighbourhood, and its two legs together hold back the four others. Measured from 1000
/// random starts on the ideal plant (`tests.rs`): 56.5 % tripods literally (the rest that wave
/// or staggered tripods), 86.7 % among the Rule-2 legs (the rest that wave, on a kinematic
/// model of the rules). The reading here keeps the priority of the most restricted
/// leg (the lowest margin, and any leg that cannot wait a step) and lets the legs that Rule 2
/// allows lift as soon as they may, as many as possible: with the six feet down that is a
/// tripod, the one that holds the lowest margin, and the other tripod follows when it lands, so
/// the wave cannot form (one leg of the pair that landed first waits a step, which its margin
/// allows, or it is urgent and lifts). A leg that has just landed does not lift again before its
/// lower-margin neighbours that still wait for a leg in the air (the last point): the priority
/// among the Rule-2 legs alone let it, on a kinematic model of the rules a leg then stepped
/// twice in a cycle while its neighbours waited, and the dynamic straight walk deadlocked 157 s
/// of 200 s.
///
/// With a failed leg (beyond the thesis, [`neighbours`]) no tripod exists: the rules are those
/// stated, a leg lifts when Rule 2 allows it and its margin is lower than both neighbours'.
/// With the priority above (as many legs as possible in the swing, then the stability filter
/// of the controller) the five-leg walks of `tests.rs` with leg 1, 2, 4 or 5 failed deadlocked
/// for good on the ideal plant (measured; with Rule 3 as stated, legs 0, 3, 4 and 5 walk).
///
/// INTERPRETATION: equal margins (feet placed symmetrically, e.g. all at their workspace centres
/// at the start of a straight walk) are ordered by the leg number (the lower number first). A
/// leg whose foot does not move (infinite margin: the robot stands still) never lifts.
pub fn swing_candidates(support: &[bool; 6], margin: &[f64; 6], neighbours: &[Option<(usize, usize)>; 6], reserve: f64) -> [bool; 6] {
    let of = |l: usize| neighbours[l].map_or([l, l], |(a, b)| [a, b]);
    // Rule 2.
    let rule_2: [bool; 6] = std::array::from_fn(|l| rule_2(l, support, neighbours) && margin[l].is_finite());
    // The priority: the lower margin, then the lower leg number.
    let order = |a: &usize, b: &usize| margin[*a].total_cmp(&margin[*b]).then(a.cmp(b));
    let before = |a: usize, b: usize| order(&a, &b).is_lt();
    // The legs Rule 2 allows that do not pass a lower-margin neighbour it holds back.
    let mut free: Vec<usize> = (0..6).filter(|&l| rule_2[l] && !of(l).iter().any(|&n| support[n] && !rule_2[n] && before(n, l))).collect();
    free.sort_by(order);
    if neighbours.iter().any(Option::is_none) {
        // A failed leg: Rule 3 as stated (the legs lower than both neighbours).
        return std::array::from_fn(|l| free.contains(&l) && of(l).iter().all(|&n| before(l, n)));
    }
    let Some(&lowest) = free.first() else {
        return [false; 6];
    };
    // The legs that must swing: the lowest margin, and the urgent ones not next to them.
    let mut must = 1u8 << lowest;
    for &l in &free[1..] {
        if margin[l] < reserve && of(l).iter().all(|&n| must & (1 << n) == 0) {
            must |= 1 << l;
        }
    }
    // The largest set of free non-neighbouring legs holding them; among sets of that size, the
    // lowest margins first (the ranks in `free`, sorted by margin, compared in order).
    let within = free.iter().fold(0u8, |m, &l| m | 1 << l);
    let independent = |set: u8| (0..6).all(|l| set & (1 << l) == 0 || of(l).iter().all(|&n| set & (1 << n) == 0));
    let ranks = |set: u8| -> Vec<usize> { (0..free.len()).filter(|&r| set & (1 << free[r]) != 0).collect() };
    let best = (0..64u8)
        .filter(|&set| set & !within == 0 && set & must == must && independent(set))
        .min_by_key(|&set| (std::cmp::Reverse(set.count_ones()), ranks(set)))
        .unwrap_or(must);
    std::array::from_fn(|l| best & (1 << l) != 0)
}

/// Section 7.7.4: the robot is deadlocked when a leg in support has reached the boundary of its
/// workspace (its margin is below `boundary`, the distance its foot moves in one control
/// period) and cannot be lifted (`lifting[l]` false).
pub fn deadlocked(support: &[bool; 6], margin: &[f64; 6], lifting: &[bool; 6], boundary: f64) -> bool {
    (0..6).any(|l| support[l] && !lifting[l] && margin[l] < boundary)
}

/// An upward push of the ground on the body through a foot that is not in support: a landing
/// foot pressing on the ground before its landing is detected. `at`: the foot's horizontal
/// position; `share`: the push over the robot's weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Push {
    pub at: Vector2<f64>,
    pub share: f64,
}

/// Static stability margin (m) of the centre of mass' horizontal position `c` over the support
/// feet `feet` (their horizontal positions), with the upward `pushes` of landing feet: the
/// largest, over the triangles of three feet, of the smallest, over the triangle's sides, of
/// the signed distance d_c from `c` to the side (positive inside) less share · d_p for each push
/// at a distance d_p > 0 inside that side. Negative when the robot tips over a side; −∞ for
/// fewer than three feet.
///
/// Moments about a side: the weight W restores with W d_c; a push F inside the side lifts the
/// support's interior about it with F d_p (a push outside it presses the interior down, and
/// cannot tip the robot over that side). The robot stays on the side's feet while
/// W d_c ≥ F d_p, i.e. d_c − (F/W) d_p ≥ 0: the margin is that of an equivalent centre of mass.
pub fn stability_margin(c: &Vector2<f64>, feet: &[Vector2<f64>], pushes: &[Push]) -> f64 {
    let mut best = f64::NEG_INFINITY;
    let n = feet.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                best = best.max(triangle_margin(c, &[feet[i], feet[j], feet[k]], pushes));
            }
        }
    }
    best
}

fn triangle_margin(c: &Vector2<f64>, t: &[Vector2<f64>; 3], pushes: &[Push]) -> f64 {
    let orientation = (t[1] - t[0]).perp(&(t[2] - t[0])).signum();
    if orientation == 0.0 {
        return f64::NEG_INFINITY;
    }
    (0..3)
        .map(|e| {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let edge = b - a;
            let inside = |p: &Vector2<f64>| orientation * edge.perp(&(p - a)) / edge.norm();
            inside(c) - pushes.iter().map(|p| p.share * inside(&p.at).max(0.0)).sum::<f64>()
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

    /// Rule 2 forbids neighbours together; Rule 3 lifts the lowest margin and, with it, as many
    /// legs as Rule 2 allows.
    #[test]
    fn rules_2_and_3() {
        let t = neighbours(None);
        let all = [true; 6];
        let margin = [0.01, 0.05, 0.06, 0.02, 0.03, 0.04];
        // The lowest margin, leg 0, and the tripod that holds it (here also the local minima along
        // 0-1-3-5-4-2: leg 3, 0.02 < 0.05, 0.04; leg 4, 0.03 < 0.04, 0.06).
        assert_eq!(swing_candidates(&all, &margin, &t, 0.0), [true, false, false, true, true, false]);
        // Leg 1 in the air: its neighbours 0 and 3 cannot swing (Rule 2), and legs 2 and 5 do
        // not pass them (lower margins); leg 4 swings.
        let mut support = all;
        support[1] = false;
        assert_eq!(swing_candidates(&support, &margin, &t, 0.0), [false, false, false, false, true, false]);
        // Leg 5 failed (circuit 0-1-3-4-2): Rule 3 as stated, only leg 0 is lower than both its
        // neighbours (leg 4, 0.04, would complete the largest set {0, 4}).
        let mut five = [true; 6];
        five[5] = false;
        let margin_5 = [0.01, 0.02, 0.03, 0.05, 0.04, f64::INFINITY];
        assert_eq!(swing_candidates(&five, &margin_5, &neighbours(Some(5)), 0.0), [true, false, false, false, false, false]);
        // Leg 0 at its boundary and not lifting: deadlock.
        let lifting = swing_candidates(&support, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &t, 0.0);
        assert!(deadlocked(&support, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &lifting, 1e-4));
        assert!(!deadlocked(&all, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &swing_candidates(&all, &[0.0, 0.05, 0.06, 0.02, 0.03, 0.04], &t, 0.0), 1e-4));
    }

    /// The wave of opposite pairs breaks: the six feet down after the pair {1, 4} landed, the
    /// pair {0, 5} (landed before {2, 3}) has the lowest margins. By margins alone both legs of
    /// {0, 5} would lift and hold back the four others (the wave); here the tripod holding leg
    /// 0 lifts and leg 5 waits a step, unless it cannot (below the reserve).
    #[test]
    fn the_wave_of_opposite_pairs_gives_way_to_a_tripod() {
        let t = neighbours(None);
        let all = [true; 6];
        let margin = [0.05, 0.15, 0.10, 0.10, 0.15, 0.051];
        assert_eq!(swing_candidates(&all, &margin, &t, 0.0), [true, false, false, true, true, false]);
        // Leg 5 cannot wait a step (0.051 m < 0.06 m): it lifts with leg 0, which leaves no
        // room for another leg (every other leg neighbours one of them).
        assert_eq!(swing_candidates(&all, &margin, &t, 0.06), [true, false, false, false, false, true]);
    }

    /// A leg of a tripod that lands before the two others does not lift again while its
    /// neighbours, with lower margins, wait for those in the air (Rule 2 holds them back).
    #[test]
    fn a_leg_just_landed_does_not_pass_its_waiting_neighbours() {
        let t = neighbours(None);
        let mut support = [true; 6];
        (support[3], support[4]) = (false, false);
        let margin = [0.17, 0.08, 0.08, f64::INFINITY, f64::INFINITY, 0.08];
        assert_eq!(swing_candidates(&support, &margin, &t, 0.0), [false; 6]);
        // Were its neighbours further from their boundaries, it would swing (Rule 2 allows it).
        let margin = [0.07, 0.08, 0.08, f64::INFINITY, f64::INFINITY, 0.08];
        assert_eq!(swing_candidates(&support, &margin, &t, 0.0), [true, false, false, false, false, false]);
    }

    #[test]
    fn stability_margin_of_a_triangle() {
        let h = 3f64.sqrt() / 2.0;
        let feet = [Vector2::new(1.0, 0.0), Vector2::new(-0.5, h), Vector2::new(-0.5, -h)];
        assert!((stability_margin(&Vector2::zeros(), &feet, &[]) - 0.5).abs() < 1e-12);
        assert!((stability_margin(&Vector2::new(-0.7, 0.0), &feet, &[]) + 0.2).abs() < 1e-12);
        assert_eq!(stability_margin(&Vector2::zeros(), &feet[..2], &[]), f64::NEG_INFINITY);
    }

    /// A push tips the robot over a side exactly when its moment about the side exceeds the
    /// weight's: a unit-weight robot with its centre of mass 0.5 inside the side x = −0.5 of a
    /// triangle, pushed at 1.5 inside it (at the opposite vertex x = 1) by a third of its
    /// weight, is at the limit (0.5 − 0.5 = 0); a push outside a side does not count against
    /// that side.
    #[test]
    fn stability_margin_with_a_landing_foots_push() {
        let h = 3f64.sqrt() / 2.0;
        let feet = [Vector2::new(1.0, 0.0), Vector2::new(-0.5, h), Vector2::new(-0.5, -h)];
        let third = Push { at: Vector2::new(1.0, 0.0), share: 1.0 / 3.0 };
        assert!(stability_margin(&Vector2::zeros(), &feet, &[third]).abs() < 1e-12);
        // A tenth of the weight: 0.5 − 0.15 on that side; the two other sides (0.5 from the
        // centre, the push on them) keep 0.5.
        let tenth = Push { share: 0.1, ..third };
        assert!((stability_margin(&Vector2::zeros(), &feet, &[tenth]) - 0.35).abs() < 1e-12);
        // Pushed from outside the side x = −0.5 (at x = −1): not against that side (0.5 stays),
        // against the two others, which it is 1.0 inside: 0.5 − 0.2 · 1.0.
        let behind = Push { at: Vector2::new(-1.0, 0.0), share: 0.2 };
        assert!((stability_margin(&Vector2::zeros(), &feet, &[behind]) - 0.3).abs() < 1e-12);
    }
}
