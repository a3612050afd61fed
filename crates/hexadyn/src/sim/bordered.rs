//! Solves with a matrix in bordered block-diagonal form, the shape of the Newmark iteration
//! matrix J (Eq. 3.14) and of the mass matrix of a legged robot.
//!
//! In minimal coordinates (Section 3.2.2) a joint moves the bodies of its own leg only, so the
//! partial velocities of two joints of different legs never meet on a body: the inertial terms
//! (Eq. 3.39), the joint friction and actuator terms and the ground contact of a foot (which
//! moves with the body's coordinates and its own leg's joints) couple the joints of a leg with
//! each other and with the six coordinates of the body only. Ordered legs first and the body
//! last, J = [[A_1, 0, …, E_1], [0, A_2, …, E_2], …, [F_1, F_2, …, A_b]]: diagonal blocks A_k
//! (3 × 3 on the AMRU5) and a border of the body's coordinates (6). Eliminating the blocks,
//! S = A_b − Σ_k F_k A_k⁻¹ E_k, and
//!
//! x_b = S⁻¹ (r_b − Σ_k F_k A_k⁻¹ r_k),  x_k = A_k⁻¹ r_k − A_k⁻¹ E_k x_b,
//!
//! with A_k⁻¹, F_k A_k⁻¹, A_k⁻¹ E_k and S⁻¹ kept as small dense matrices: a solve of the AMRU5's
//! 24 × 24 matrix is 306 products in short contiguous rows instead of the 576 of the LU's
//! triangular solves, and the factorization inverts six 3 × 3 blocks and one 6 × 6 matrix
//! instead of factoring the 24 × 24.
//!
//! The structure is read from the matrix's zeros (nothing is assumed about the model): the
//! border is the set of the most connected coordinates whose removal splits the rest into
//! independent blocks, tried where the connectivity drops; the next factorization keeps it while
//! the zeros between its blocks hold (it is the tree's, and holds for the whole walk). The
//! elimination is used only when
//! it bounds the element growth as [`super::factorization`] does for the first-order states:
//! the largest entry of Σ_k F_k A_k⁻¹ E_k is at most 1 / [`PIVOT_THRESHOLD`] times the largest
//! entry of A_b. INTERPRETATION: the thesis solves Eq. 3.14 with a dense LU (Section 3.3.2).

use nalgebra::DMatrix;

use super::factorization::PIVOT_THRESHOLD;

/// The elimination is kept only when its solve takes at most this share of the products of the
/// dense solve (n²): small systems, where the gain is in the noise, keep the LU with partial
/// pivoting.
const WORTH_BELOW: f64 = 0.75;

/// Four lanes of a vector padded to whole groups: the kernels work on whole groups, which the
/// compiler turns into vector instructions (the blocks and the border are a few coordinates
/// each, too short for loops over single entries to pay for their set-up).
type Lanes = [f64; LANES];
const LANES: usize = 4;

/// The largest block and border the elimination takes, in groups of lanes (8 coordinates): the
/// kernels are unrolled for them, and larger ones are left to the dense LU.
const MAX_GROUPS: usize = 2;

/// y + Σ_j x_j column_j over columns of G groups, y kept in registers.
#[inline(always)]
fn accumulate<const G: usize>(mut y: [Lanes; G], columns: &[Lanes], x: impl Iterator<Item = f64>) -> [Lanes; G] {
    for (column, xj) in columns.chunks_exact(G).zip(x) {
        for (s, c) in y.iter_mut().zip(column) {
            for l in 0..LANES {
                s[l] += xj * c[l];
            }
        }
    }
    y
}

/// The columns of a small dense matrix appended to `data`, each padded with zeros to `groups`.
fn push_columns(data: &mut Vec<Lanes>, m: &DMatrix<f64>, groups: usize) {
    for column in m.as_slice().chunks_exact(m.nrows()) {
        let mut padded = [[0.0; LANES]; MAX_GROUPS];
        padded.as_flattened_mut()[..column.len()].copy_from_slice(column);
        data.extend_from_slice(&padded[..groups]);
    }
}

/// The elimination order of a bordered block-diagonal matrix: its rows block after block, then
/// the border's, and the size of each block.
#[derive(Clone, Debug, PartialEq)]
struct Structure {
    order: Vec<usize>,
    sizes: Vec<usize>,
}

impl Structure {
    /// The structure of `a`, when removing the coordinates of highest connectivity splits the
    /// others into at least two independent blocks with a solve cheaper than [`WORTH_BELOW`] of
    /// the dense one (each block in increasing order, the border too). Two coordinates are
    /// connected when either of their couplings is non-zero. The border sizes tried are those
    /// where the connectivity, sorted, drops.
    fn find(a: &DMatrix<f64>) -> Option<Self> {
        let n = a.nrows();
        // coupled[i n + j]: from the column-major entries, either way round.
        let mut coupled = vec![false; n * n];
        for (j, column) in a.as_slice().chunks_exact(n).enumerate() {
            for (i, _) in column.iter().enumerate().filter(|&(i, &v)| v != 0.0 && i != j) {
                coupled[i * n + j] = true;
                coupled[j * n + i] = true;
            }
        }
        let degree: Vec<usize> = coupled.chunks_exact(n).map(|row| row.iter().filter(|&&c| c).count()).collect();
        let mut by_degree: Vec<usize> = (0..n).collect();
        by_degree.sort_by_key(|&i| std::cmp::Reverse(degree[i]));
        let mut best: Option<(usize, Structure)> = None;
        for size in (1..=n / 2).filter(|&k| degree[by_degree[k - 1]] > degree[by_degree[k]]) {
            let mut border: Vec<usize> = by_degree[..size].to_vec();
            border.sort_unstable();
            let blocks = components(&coupled, &border);
            let products = blocks.iter().map(|b| b.len() * b.len() + 2 * size * b.len()).sum::<usize>() + size * size;
            if blocks.len() >= 2 && products as f64 <= WORTH_BELOW * (n * n) as f64 && best.as_ref().is_none_or(|(p, _)| products < *p) {
                let sizes = blocks.iter().map(Vec::len).collect();
                let order = blocks.into_iter().flatten().chain(border).collect();
                best = Some((products, Structure { order, sizes }));
            }
        }
        best.map(|(_, s)| s)
    }

    /// Whether the entries of `a` between different blocks are all zero.
    fn holds_for(&self, a: &DMatrix<f64>) -> bool {
        let n = a.nrows();
        if n != self.order.len() {
            return false;
        }
        let mut block_of = vec![usize::MAX; n];
        let mut rows = self.order.iter();
        for (k, &size) in self.sizes.iter().enumerate() {
            rows.by_ref().take(size).for_each(|&i| block_of[i] = k);
        }
        a.as_slice().chunks_exact(n).zip(&block_of).all(|(column, &bj)| bj == usize::MAX || column.iter().zip(&block_of).all(|(&v, &bi)| v == 0.0 || bi == bj || bi == usize::MAX))
    }
}

/// Connected components of the coordinates outside `border`, each in increasing order
/// (`coupled`: n × n, row-major).
fn components(coupled: &[bool], border: &[usize]) -> Vec<Vec<usize>> {
    let n = coupled.len().isqrt();
    let mut seen = vec![false; n];
    border.iter().for_each(|&i| seen[i] = true);
    let mut blocks: Vec<Vec<usize>> = Vec::new();
    for seed in 0..n {
        if seen[seed] {
            continue;
        }
        let (mut members, mut next) = (vec![seed], 0);
        seen[seed] = true;
        while next < members.len() {
            let row = &coupled[members[next] * n..(members[next] + 1) * n];
            next += 1;
            for (j, _) in row.iter().enumerate().filter(|&(_, &c)| c) {
                if !seen[j] {
                    seen[j] = true;
                    members.push(j);
                }
            }
        }
        members.sort_unstable();
        blocks.push(members);
    }
    blocks
}

/// Inverses of the blocks and of the border's Schur complement of a bordered block-diagonal
/// matrix (see the module documentation), as columns padded to whole groups.
#[derive(Clone, Debug)]
pub(crate) struct Bordered {
    structure: Structure,
    /// The entries of the solved vectors that the matrix's rows are.
    entries: Vec<usize>,
    /// `entries` in elimination order: where the solve reads and writes.
    targets: Vec<usize>,
    /// Per block: [A_k⁻¹, −A_k⁻¹ E_k], over the block's coordinates then the border's.
    blocks: Vec<Vec<Lanes>>,
    /// [−F_1 A_1⁻¹, −F_2 A_2⁻¹, …], over the blocks' coordinates.
    to_border: Vec<Lanes>,
    /// S⁻¹.
    schur_inverse: Vec<Lanes>,
    /// Size of the border, and groups of a block's and of the border's columns.
    border: usize,
    block_groups: usize,
    border_groups: usize,
}

impl Bordered {
    /// The elimination of `a`, when its zeros make it bordered block-diagonal (the structure of
    /// `previous` when it still holds, else [`Structure::find`]), its blocks and Schur
    /// complement are invertible and the growth stays bounded; None otherwise (the caller's
    /// dense LU then decides). Row i of `a` is entry `entries[i]` of the vectors
    /// [`Self::solve_mut`] solves for.
    pub(crate) fn new(a: &DMatrix<f64>, entries: &[usize], previous: Option<&Bordered>) -> Option<Self> {
        let structure = match previous {
            Some(p) if p.entries == entries && p.structure.holds_for(a) => p.structure.clone(),
            _ => Structure::find(a)?,
        };
        let n = a.nrows();
        let in_blocks: usize = structure.sizes.iter().sum();
        let nb = n - in_blocks;
        let (border_groups, block_groups) = (nb.div_ceil(LANES), structure.sizes.iter().max()?.div_ceil(LANES));
        if border_groups > MAX_GROUPS || block_groups > MAX_GROUPS {
            return None;
        }
        // a in elimination order: the blocks A_k on the diagonal, E_k and F_k against the border.
        let order = &structure.order;
        let p = DMatrix::from_fn(n, n, |r, c| a[(order[r], order[c])]);
        let a_b = p.view((in_blocks, in_blocks), (nb, nb));
        let mut schur = a_b.clone_owned();
        let (mut blocks, mut to_border) = (Vec::with_capacity(structure.sizes.len()), Vec::with_capacity(in_blocks * border_groups));
        let mut start = 0;
        for &size in &structure.sizes {
            let inverse = p.view((start, start), (size, size)).clone_owned().try_inverse()?;
            let f_k = p.view((in_blocks, start), (nb, size));
            let from_border = &inverse * p.view((start, in_blocks), (size, nb));
            schur.gemm(-1.0, &f_k, &from_border, 1.0);
            push_columns(&mut to_border, &(f_k * &inverse * -1.0), border_groups);
            let mut columns = Vec::with_capacity((size + nb) * block_groups);
            push_columns(&mut columns, &inverse, block_groups);
            push_columns(&mut columns, &-from_border, block_groups);
            blocks.push(columns);
            start += size;
        }
        if !((a_b - &schur).amax() * PIVOT_THRESHOLD <= a_b.amax()) {
            return None;
        }
        let inverse = schur.try_inverse()?;
        if !inverse.iter().all(|v| v.is_finite()) {
            return None;
        }
        let mut schur_inverse = Vec::with_capacity(nb * border_groups);
        push_columns(&mut schur_inverse, &inverse, border_groups);
        let targets = order.iter().map(|&i| entries[i]).collect();
        Some(Bordered { structure, entries: entries.to_vec(), targets, blocks, to_border, schur_inverse, border: nb, block_groups, border_groups })
    }

    /// Overwrites the entries of r that are the matrix's rows with x, A x = r.
    pub(crate) fn solve_mut(&self, r: &mut [f64]) {
        match (self.block_groups, self.border_groups) {
            (1, 1) => self.solve_in_groups::<1, 1>(r),
            (1, 2) => self.solve_in_groups::<1, 2>(r),
            (2, 1) => self.solve_in_groups::<2, 1>(r),
            (2, 2) => self.solve_in_groups::<2, 2>(r),
            _ => unreachable!("at most MAX_GROUPS groups (Bordered::new)"),
        }
    }

    /// [`Self::solve_mut`] with blocks of B groups and a border of N.
    fn solve_in_groups<const B: usize, const N: usize>(&self, r: &mut [f64]) {
        let (block_targets, border) = self.targets.split_at(self.targets.len() - self.border);
        // t = r_b − Σ_k F_k A_k⁻¹ r_k, then x_b = S⁻¹ t.
        let mut t = [[0.0; LANES]; N];
        for (k, &i) in border.iter().enumerate() {
            t[k / LANES][k % LANES] = r[i];
        }
        let t = accumulate(t, &self.to_border, block_targets.iter().map(|&i| r[i]));
        let x_b = accumulate([[0.0; LANES]; N], &self.schur_inverse, t.as_flattened()[..self.border].iter().copied());
        let x_b = &x_b.as_flattened()[..self.border];
        // x_k = A_k⁻¹ r_k − A_k⁻¹ E_k x_b: each block reads and writes its own coordinates only.
        let mut start = 0;
        for (columns, &size) in self.blocks.iter().zip(&self.structure.sizes) {
            let targets = &block_targets[start..start + size];
            let (inverse, from_border) = columns.split_at(size * B);
            let x_k = accumulate([[0.0; LANES]; B], inverse, targets.iter().map(|&i| r[i]));
            let x_k = accumulate(x_k, from_border, x_b.iter().copied());
            for (&v, &i) in x_k.as_flattened().iter().zip(targets) {
                r[i] = v;
            }
            start += size;
        }
        for (&v, &i) in x_b.iter().zip(border) {
            r[i] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DVector, LU};
    use rand::{Rng, SeedableRng};

    /// A matrix of the AMRU5's shape: a border of 6 coordinates (the body's, placed at
    /// `border`) coupled with everything, and 6 legs of 3 joints coupled among themselves,
    /// reflected inertias from 1e-2 to 1e3 on the diagonal.
    fn hexapod_shaped(rng: &mut impl Rng, border: &[usize]) -> DMatrix<f64> {
        let n = 24;
        let legs: Vec<usize> = (0..n).filter(|i| !border.contains(i)).collect();
        let leg_of = |i: usize| legs.iter().position(|&j| j == i).map(|k| k / 3);
        let mut a = DMatrix::from_fn(n, n, |r, c| match (leg_of(r), leg_of(c)) {
            (Some(x), Some(y)) if x != y => 0.0,
            _ => rng.random_range(-1.0..1.0),
        });
        for i in 0..n {
            a[(i, i)] += 10f64.powf(rng.random_range(-2.0..3.0)) * if leg_of(i).is_some() { 1.0 } else { 30.0 };
        }
        a
    }

    /// The structure is found wherever the body's coordinates sit, the solve agrees with the
    /// LU with partial pivoting and has its backward error: ‖A x − r‖ ≤ 1e-14 ‖A‖ ‖x‖.
    #[test]
    fn solves_hexapod_shaped_matrices_as_the_dense_lu() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for (trial, border) in [[0, 1, 2, 3, 4, 5], [18, 19, 20, 21, 22, 23], [0, 4, 8, 12, 16, 20]].iter().cycle().take(300).enumerate() {
            let a = hexapod_shaped(&mut rng, border);
            let found = Structure::find(&a).expect("bordered");
            assert_eq!(&found.order[18..], border, "trial {trial}");
            assert_eq!(found.sizes, [3; 6]);
            let e = Bordered::new(&a, &(0..24).collect::<Vec<_>>(), None).expect("eliminable");
            let r: Vec<f64> = (0..24).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut x = r.clone();
            e.solve_mut(&mut x);
            let x = DVector::from_vec(x);
            let lu = LU::new(a.clone()).solve(&DVector::from_column_slice(&r)).unwrap();
            let norm = (0..24).map(|i| a.row(i).iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
            let residual = (&a * &x - DVector::from_column_slice(&r)).amax();
            assert!(residual <= 1e-14 * norm * x.amax(), "trial {trial}: backward error {:e}", residual / (norm * x.amax()));
            assert!((&x - &lu).amax() <= 1e-10 * lu.amax(), "trial {trial}: {x} vs {lu}");
        }
    }

    /// A dense matrix, a single block and a small system keep the dense LU.
    #[test]
    fn no_elimination_without_the_structure_or_the_gain() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let dense = DMatrix::from_fn(12, 12, |r, c| if r == c { 10.0 } else { rng.random_range(-1.0..1.0) });
        assert!(Structure::find(&dense).is_none());
        // An arrow whose shaft is one chain: removing the head leaves one block.
        let chain = DMatrix::from_fn(8, 8, |r, c| if r == 0 || c == 0 || r.abs_diff(c) <= 1 { 1.0 + (r + c) as f64 } else { 0.0 });
        assert!(Structure::find(&chain).is_none());
        // 3 × 3 arrow: 7 products against 9, not worth it.
        let arrow = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 1.0, 1.0, 3.0, 0.0, 1.0, 0.0, 2.0]);
        assert!(Structure::find(&arrow).is_none());
    }

    /// A leg block whose pivot is tiny against its coupling to the body would swamp the border
    /// (growth beyond 1 / PIVOT_THRESHOLD): left to the dense LU's partial pivoting.
    #[test]
    fn growth_beyond_the_threshold_is_left_to_the_lu() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let border = [0, 1, 2, 3, 4, 5];
        let a = hexapod_shaped(&mut rng, &border);
        let all: Vec<usize> = (0..24).collect();
        assert!(Bordered::new(&a, &all, None).is_some());
        let mut swamping = a.clone();
        let leg: Vec<usize> = (6..9).collect();
        for &i in &leg {
            for &j in &leg {
                swamping[(i, j)] *= 1e-9;
            }
        }
        assert!(Structure::find(&swamping).is_some());
        assert!(Bordered::new(&swamping, &all, None).is_none());
    }

    /// The structure of the previous factorization is kept while the zeros between its blocks
    /// hold: the same solver as found afresh; a coupling between two legs, or other entries,
    /// make it look again.
    #[test]
    fn the_previous_structure_is_kept_while_it_holds() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let border = [0, 1, 2, 3, 4, 5];
        let all: Vec<usize> = (0..24).collect();
        let first = Bordered::new(&hexapod_shaped(&mut rng, &border), &all, None).unwrap();
        let a = hexapod_shaped(&mut rng, &border);
        let kept = Bordered::new(&a, &all, Some(&first)).unwrap();
        let fresh = Bordered::new(&a, &all, None).unwrap();
        assert_eq!(kept.structure, fresh.structure);
        let r: Vec<f64> = (0..24).map(|_| rng.random_range(-1.0..1.0)).collect();
        let (mut x, mut y) = (r.clone(), r.clone());
        kept.solve_mut(&mut x);
        fresh.solve_mut(&mut y);
        assert_eq!(x, y);
        let mut legs_coupled = a.clone();
        legs_coupled[(6, 9)] = 0.5;
        assert!(!first.structure.holds_for(&legs_coupled));
        let other_entries: Vec<usize> = (1..25).collect();
        let relabelled = Bordered::new(&a, &other_entries, Some(&first)).unwrap();
        let mut z = vec![0.0; 25];
        z[1..].copy_from_slice(&r);
        relabelled.solve_mut(&mut z);
        assert_eq!(z[0], 0.0);
        assert_eq!(&z[1..], &y[..]);
    }
}
