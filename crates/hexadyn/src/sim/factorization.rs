//! Factorization of the Newmark iteration matrix J (Eq. 3.14) and of M = ∂f/∂q'', reduced
//! onto the coupled coordinates when some first-order states are decoupled from each other.
//!
//! First-order states such as the LuGre bristle deflections (Eq. 3.85) or the motor currents
//! (Eq. 3.91) each depend on their own value and on the velocity of their joint only: ordering
//! the coordinates as (a, t), t those states, J = [[A, B], [C, D]] with D diagonal and B, C
//! sparse. J x = r is then solved exactly through the Schur complement S = A − B D⁻¹ C:
//! S x_a = r_a − B D⁻¹ r_t, x_t = D⁻¹ (r_t − C x_a). For the 42-DOF model (24 multibody
//! coordinates, 18 bristles) the LU is that of a 24 × 24 matrix instead of 42 × 42, about a
//! fifth of the work, and each solve about half. S (or J when nothing is eliminated) is then
//! solved by its bordered block-diagonal elimination when the tree's zeros allow it
//! (`bordered.rs`), else by its LU with partial pivoting.

use nalgebra::{DMatrix, DVector, Dyn, LU};

use super::bordered::Bordered;

/// A decoupled state t is eliminated only when its pivot keeps the element growth of the
/// elimination bounded: the largest update of the Schur complement, max|J_kt| · max|J_tl| / |J_tt|,
/// is at most 1 / `PIVOT_THRESHOLD` times the largest diagonal entry of the block that is never
/// eliminated (the second-order coordinates). This is the growth bound of threshold partial
/// pivoting with threshold u = `PIVOT_THRESHOLD` (an entry of S grows by at most 1/u times the
/// largest entry of A for each eliminated state that updates it), and unlike a test of |J_tt|
/// against its own row and column it does not depend on the units of the state: a LuGre
/// bristle row (in m/s) against the stiff column σ0 γh (in N/m · s) of a nut joint passes it,
/// its update σ0 γ²h² / J_tt being of the size of the reflected rotor inertias it is added to
/// (the dominance test kept 12 of the 18 bristles of the 75 s walk in the LU: 36 × 36 instead
/// of 24 × 24).
pub(crate) const PIVOT_THRESHOLD: f64 = 1e-3;

/// Whether first-order state `i` can be eliminated: no coupling to another first-order state and
/// a pivot that bounds the growth against `kept` (see [`PIVOT_THRESHOLD`]). One pass over its
/// row and column.
fn eliminable(j: &DMatrix<f64>, first_order: &[bool], i: usize, kept: f64) -> bool {
    // Column-major storage: column i is contiguous, row i strided by n.
    let (n, entries) = (j.nrows(), j.as_slice());
    let own_column = &entries[i * n..(i + 1) * n];
    let (mut column, mut row, mut coupled) = (0.0_f64, 0.0_f64, false);
    for k in 0..n {
        if k != i {
            let (down, across) = (own_column[k].abs(), entries[k * n + i].abs());
            column = if down > column { down } else { column };
            row = if across > row { across } else { row };
            coupled |= first_order[k] & (down != 0.0 || across != 0.0);
        }
    }
    let diagonal = j[(i, i)].abs();
    diagonal > 0.0 && !coupled && column * row * PIVOT_THRESHOLD <= diagonal * kept
}

/// LU factorization of J, on the Schur complement when first-order states can be eliminated.
#[derive(Clone, Debug)]
pub(crate) struct Factorization {
    kind: Kind,
}

#[derive(Clone, Debug)]
enum Kind {
    Full(Dense),
    Reduced(Reduced),
}

/// The solver of the matrix left after the first-order states: its bordered block-diagonal
/// elimination when its zeros allow it ([`Bordered`]), else its LU with partial pivoting.
#[derive(Clone, Debug)]
enum Dense {
    Lu(LU<f64, Dyn, Dyn>),
    Bordered(Bordered),
}

impl Dense {
    /// The solver of `m`, whose rows are the entries `coordinates` of the vectors it will solve
    /// for, in the structure of `previous` when that still holds. None when `m` is singular.
    fn new(m: DMatrix<f64>, coordinates: &[usize], previous: Option<&Factorization>) -> Option<Self> {
        let previous = previous.and_then(|p| match &p.kind {
            Kind::Full(Dense::Bordered(b)) | Kind::Reduced(Reduced { lu: Dense::Bordered(b), .. }) => Some(b),
            _ => None,
        });
        if let Some(b) = Bordered::new(&m, coordinates, previous) {
            return Some(Dense::Bordered(b));
        }
        let lu = LU::new(m);
        lu.is_invertible().then_some(Dense::Lu(lu))
    }

    /// Overwrites the entries `coordinates` of x (all of them when None) with the solution for
    /// them; false when the LU cannot solve it.
    fn solve_entries(&self, x: &mut DVector<f64>, coordinates: Option<&[usize]>) -> bool {
        match (self, coordinates) {
            (Dense::Bordered(b), _) => {
                b.solve_mut(x.as_mut_slice());
                true
            }
            (Dense::Lu(lu), None) => lu.solve_mut(x),
            (Dense::Lu(lu), Some(coordinates)) => {
                let mut part = DVector::from_iterator(coordinates.len(), coordinates.iter().map(|&i| x[i]));
                let solved = lu.solve_mut(&mut part);
                coordinates.iter().zip(part.iter()).for_each(|(&i, &v)| x[i] = v);
                solved
            }
        }
    }
}

#[derive(Clone, Debug)]
struct Reduced {
    /// Coordinates of the coupled block, and the eliminated states with their diagonal D.
    a: Vec<usize>,
    t: Vec<usize>,
    d: Vec<f64>,
    /// Non-zero entries of B (position in `a`, position in `t`, value) and of C (position in
    /// `t`, position in `a`, value).
    b: Vec<(usize, usize, f64)>,
    c: Vec<(usize, usize, f64)>,
    /// Solver of S = A − B D⁻¹ C.
    lu: Dense,
}

impl Factorization {
    /// Factorizes `j`, eliminating the `first_order` coordinates that are decoupled from every
    /// other first-order coordinate and whose pivot bounds the growth (see [`PIVOT_THRESHOLD`]),
    /// the rest in the block structure of `previous` (the last factorization of the same
    /// matrix) while it holds ([`Bordered`]). None when J is singular.
    pub(crate) fn new(j: DMatrix<f64>, first_order: &[bool], previous: Option<&Factorization>) -> Option<Self> {
        let n = j.nrows();
        // The largest diagonal entry of the block never eliminated: a lower bound of its largest
        // entry, so that the test is the stricter for it.
        let kept = (0..n).filter(|&r| !first_order[r]).fold(0.0_f64, |m, r| m.max(j[(r, r)].abs()));
        let t: Vec<usize> = (0..n).filter(|&i| first_order[i] && eliminable(&j, first_order, i, kept)).collect();
        // Nothing to eliminate, or nothing left (a diagonal J): J itself is solved.
        if t.is_empty() || t.len() == n {
            let all: Vec<usize> = (0..n).collect();
            return Dense::new(j, &all, previous).map(|lu| Factorization { kind: Kind::Full(lu) });
        }
        let mut in_t = vec![false; n];
        t.iter().for_each(|&i| in_t[i] = true);
        let a: Vec<usize> = (0..n).filter(|&i| !in_t[i]).collect();
        let d: Vec<f64> = t.iter().map(|&i| j[(i, i)]).collect();
        let mut b = Vec::new();
        let mut c = Vec::new();
        // C row by row: those of row kt from c_start[kt].
        let mut c_start = Vec::with_capacity(t.len() + 1);
        for (kt, &ti) in t.iter().enumerate() {
            c_start.push(c.len());
            for (ka, &ai) in a.iter().enumerate() {
                if j[(ai, ti)] != 0.0 {
                    b.push((ka, kt, j[(ai, ti)]));
                }
                if j[(ti, ai)] != 0.0 {
                    c.push((kt, ka, j[(ti, ai)]));
                }
            }
        }
        c_start.push(c.len());
        let mut s = DMatrix::from_fn(a.len(), a.len(), |r, col| j[(a[r], a[col])]);
        for &(ka, kt, bv) in &b {
            let scale = bv / d[kt];
            for &(_, cj, cv) in &c[c_start[kt]..c_start[kt + 1]] {
                s[(ka, cj)] -= scale * cv;
            }
        }
        Dense::new(s, &a, previous).map(|lu| Factorization { kind: Kind::Reduced(Reduced { a, t, d, b, c, lu }) })
    }

    /// x with J x = r; None when the factorization cannot solve it. Solved in place in x.
    pub(crate) fn solve(&self, r: &[f64]) -> Option<DVector<f64>> {
        let mut x = DVector::from_column_slice(r);
        match &self.kind {
            Kind::Full(lu) => lu.solve_entries(&mut x, None).then_some(x),
            Kind::Reduced(s) => {
                // S x_a = r_a − B D⁻¹ r_t.
                for &(ka, kt, bv) in &s.b {
                    x[s.a[ka]] -= bv * (r[s.t[kt]] / s.d[kt]);
                }
                if !s.lu.solve_entries(&mut x, Some(&s.a)) {
                    return None;
                }
                // x_t = D⁻¹ (r_t − C x_a).
                for &(kt, ka, cv) in &s.c {
                    x[s.t[kt]] -= cv * x[s.a[ka]];
                }
                for (kt, &i) in s.t.iter().enumerate() {
                    x[i] /= s.d[kt];
                }
                Some(x)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5 × 5 system with two decoupled first-order states: the reduced solve is the full LU's
    /// to rounding, and a coupled pair of first-order states is not eliminated.
    #[test]
    fn reduced_solve_matches_the_full_lu() {
        let j = DMatrix::from_row_slice(5, 5, &[
            4.0, 1.0, 0.5, 0.3, 0.0, //
            1.0, 3.0, 0.2, 0.0, -0.7, //
            0.5, 0.2, 5.0, 0.0, 0.0, //
            0.9, 0.0, 0.0, 2.0, 0.0, //
            0.0, -0.4, 0.0, 0.0, 1.5,
        ]);
        let r = [1.0, -2.0, 0.5, 3.0, -1.0];
        let full = LU::new(j.clone()).solve(&DVector::from_column_slice(&r)).unwrap();
        let first = [false, false, false, true, true];
        let reduced = Factorization::new(j.clone(), &first, None).unwrap();
        assert!(matches!(&reduced.kind, Kind::Reduced(s) if s.t == [3, 4]));
        let x = reduced.solve(&r).unwrap();
        assert!((&x - &full).amax() < 1e-14 * full.amax(), "{x} vs {full}");
        assert!((&j * &x - DVector::from_column_slice(&r)).amax() < 1e-13);
        // States 3 and 4 coupled to each other: neither is eliminated.
        let mut coupled = j.clone();
        coupled[(3, 4)] = 0.1;
        let f = Factorization::new(coupled, &first, None).unwrap();
        assert!(matches!(f.kind, Kind::Full(_)));
        // Every coordinate decoupled (a diagonal J): the full LU, which solves it.
        let diagonal = DMatrix::from_diagonal(&DVector::from_column_slice(&[2.0, 4.0]));
        let f = Factorization::new(diagonal, &[true, true], None).unwrap();
        assert!(matches!(f.kind, Kind::Full(_)));
        assert_eq!(f.solve(&[1.0, 1.0]).unwrap().as_slice(), &[0.5, 0.25]);
    }

    /// A LuGre bristle on a nut joint (Eq. 3.85 in the Newmark matrix, Eq. 3.14): its row in
    /// m/s, its column σ0 γh = 1e9 · 2.5e-3 N/m·s in the joint row, far above its unit diagonal,
    /// but its update σ0 γ²h² = 6250 kg of the size of the reflected rotor inertias: eliminated,
    /// and the solve is the full LU's to rounding. The same state with a row a million times
    /// larger would add 6.25e9 kg to a block of 2000: kept in the LU.
    #[test]
    fn stiff_bristle_is_eliminated_while_the_growth_stays_bounded() {
        let j = DMatrix::from_row_slice(3, 3, &[
            2000.0, 10.0, 2.5e6, //
            10.0, 500.0, 0.0, //
            -2.5e-3, 0.0, 1.0,
        ]);
        let r = [3.0, -1.0, 2e-4];
        let full = LU::new(j.clone()).solve(&DVector::from_column_slice(&r)).unwrap();
        let first = [false, false, true];
        let reduced = Factorization::new(j.clone(), &first, None).unwrap();
        assert!(matches!(&reduced.kind, Kind::Reduced(s) if s.t == [2]));
        let x = reduced.solve(&r).unwrap();
        for i in 0..3 {
            assert!((x[i] - full[i]).abs() <= 1e-13 * full[i].abs(), "{x} vs {full}");
        }
        let mut swamping = j;
        swamping[(2, 0)] = -2.5e3;
        assert!(matches!(Factorization::new(swamping, &first, None).unwrap().kind, Kind::Full(_)));
    }

    /// Random Newmark matrices of the 42-DOF LuGre model's shape (Eq. 3.14): 24 coupled
    /// coordinates with reflected inertias of 1 to 1e4 on the diagonal, one bristle per joint
    /// (Eq. 3.85: row −γh on its joint's velocity, diagonal 1 + γh σ0 |v| / g, sticking to
    /// sliding; column σ1 + γh σ0 in its joint row with σ0 from 1e4 to 1e9), h from 0.1 to
    /// 10 ms. Every bristle is eliminated, and the reduced solve has the backward error of the
    /// full LU: ‖J x − r‖ ≤ 1e-14 ‖J‖ ‖x‖ (row-sum norms). Every other matrix has the legs'
    /// joints uncoupled from the other legs' (the tree's zeros): S is then solved by the bordered
    /// elimination, on the entries of x that are its rows.
    #[test]
    fn reduced_solve_is_backward_stable_on_lugre_shaped_matrices() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(16);
        let (na, nt) = (24, 18);
        let n = na + nt;
        let other_legs = |r: usize, c: usize| r >= 6 && c >= 6 && (r - 6) / 3 != (c - 6) / 3;
        for trial in 0..200 {
            let (gamma_h, stiffness) = (0.5 * 10f64.powf(rng.random_range(-4.0..-2.0)), 10f64.powf(rng.random_range(4.0..9.0)));
            let tree = trial % 2 == 1;
            let mut j = DMatrix::from_fn(n, n, |r, c| if r < na && c < na && !(tree && other_legs(r, c)) { rng.random_range(-1.0..1.0) } else { 0.0 });
            for k in 0..na {
                j[(k, k)] += 10f64.powf(rng.random_range(0.0..4.0));
            }
            for k in 0..nt {
                let (joint, z) = (6 + k, na + k);
                let sliding = rng.random_range(0.0..1.0) * 1e-3 * stiffness;
                j[(z, z)] = 1.0 + gamma_h * sliding;
                j[(z, joint)] = -gamma_h;
                j[(joint, z)] = 1e3 * rng.random_range(0.0..1.0) + gamma_h * stiffness;
            }
            let r: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let first: Vec<bool> = (0..n).map(|i| i >= na).collect();
            let f = Factorization::new(j.clone(), &first, None).unwrap();
            assert!(matches!(&f.kind, Kind::Reduced(s) if s.t.len() == nt && matches!(s.lu, Dense::Bordered(_)) == tree));
            let x = f.solve(&r).unwrap();
            let residual = (&j * &x - DVector::from_column_slice(&r)).amax();
            let norm = (0..n).map(|i| j.row(i).iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
            assert!(residual <= 1e-14 * norm * x.amax(), "backward error {} (‖J‖ {norm:e}, ‖x‖ {:e})", residual / (norm * x.amax()), x.amax());
        }
    }

    /// A singular matrix has no factorization, reduced or not.
    #[test]
    fn singular_is_none() {
        let j = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 0.0, 2.0, 4.0, 0.0, 0.0, 0.0, 1.0]);
        assert!(Factorization::new(j.clone(), &[false, false, true], None).is_none());
        assert!(Factorization::new(j, &[false; 3], None).is_none());
    }
}
