//! Broyden's update of the kept Newmark iteration matrix within one step's Newton iteration
//! (Section 3.3.2 keeps the matrix from step to step: modified Newton).
//!
//! The good Broyden update B_{k+1} = B_k + (y_k − B_k s_k) s_kᵀ / ⟨s_k, s_k⟩ (y_k the change of
//! the residual over the step s_k) makes the kept matrix B_0 = J (Eq. 3.14) follow the residual
//! along the iteration, so that the iteration converges superlinearly where modified Newton only
//! contracts linearly. It is applied in Kelley's product form (C. T. Kelley, *Iterative Methods
//! for Linear and Nonlinear Equations*, SIAM 1995, Section 7.3, Algorithm `brsol`): B_k is never
//! formed, its inverse acts on the Newton step of B_0 through the stored steps only, which
//! costs a few vector operations per iteration and no evaluation.
//!
//! INTERPRETATION: the thesis does not say how its modified Newton iteration is accelerated.
//! The update lives within one step's iteration (the history is cleared when a step starts, when
//! the Jacobian is refreshed and when a correction is halved), in the metric of the Newton test.
//! On the 75 s LuGre walk it takes a third of the Jacobian refreshes and factorizations off
//! (docs/performance-log.md, session 28).

use nalgebra::DVector;

/// The product form divides by 1 − ⟨s_n, z⟩/⟨s_n, s_n⟩, which vanishes when the update makes
/// B_{n+1} singular along s_n. Below this value the Broyden step would be more than ten times
/// the one of the plain product: the history is dropped and the step of B_0 is taken.
const RESTART_BELOW: f64 = 0.1;

/// The steps s_0 … s_n of the current iteration, taken since it last restarted from B_0 (the
/// matrix factorized, a new step attempt, a halved correction, or a singular update).
#[derive(Debug, Default)]
pub(crate) struct Broyden {
    steps: Vec<DVector<f64>>,
}

impl Broyden {
    /// Forgets the steps: the next step is that of B_0.
    pub(crate) fn clear(&mut self) {
        self.steps.clear();
    }

    /// The next step s_{n+1} = −B_{n+1}⁻¹ f from the step of B_0, `newton` = −B_0⁻¹ f
    /// (Kelley's `brsol`: z = newton, z ← z + s_{j+1} ⟨s_j, z⟩/⟨s_j, s_j⟩ for j < n, then
    /// s_{n+1} = z / (1 − ⟨s_n, z⟩/⟨s_n, s_n⟩)), with the inner product `dot`. The step is
    /// remembered for the next one. The formulas are odd in the steps: given the corrections
    /// B_0⁻¹ f throughout, it returns the corrections B_{n+1}⁻¹ f.
    pub(crate) fn step(&mut self, newton: DVector<f64>, dot: impl Fn(&DVector<f64>, &DVector<f64>) -> f64) -> DVector<f64> {
        let step = match self.steps.split_last() {
            None => newton,
            Some((last, earlier)) => {
                let mut z = newton.clone();
                for (j, s) in earlier.iter().enumerate() {
                    z.axpy(dot(s, &z) / dot(s, s), &self.steps[j + 1], 1.0);
                }
                let denominator = 1.0 - dot(last, &z) / dot(last, last);
                if denominator.abs() > RESTART_BELOW && denominator.is_finite() {
                    z / denominator
                } else {
                    self.steps.clear();
                    newton
                }
            }
        };
        self.steps.push(step.clone());
        step
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// On a linear system A x = b, Broyden's method from B_0 ≠ A terminates in at most 2n steps
    /// (Gay, SIAM J. Numer. Anal. 16, 1979), in any inner product; modified Newton with the same
    /// B_0 only contracts by the spectral radius of I − B_0⁻¹A (here 0.56) per step.
    #[test]
    fn terminates_on_a_linear_system_within_2n_steps() {
        let a = DMatrix::from_row_slice(5, 5, &[
            4.0, 1.0, 0.0, 0.5, 0.0, //
            -1.0, 3.0, 0.7, 0.0, 0.2, //
            0.0, 0.4, 5.0, -1.0, 0.0, //
            0.3, 0.0, 1.0, 2.0, 0.5, //
            0.0, -0.6, 0.0, 0.8, 3.5,
        ]);
        let b = DVector::from_column_slice(&[1.0, -2.0, 0.5, 3.0, -1.0]);
        let b0 = DMatrix::from_diagonal(&a.diagonal()) * 2.0;
        let lu = b0.clone().lu();
        let weights = DVector::from_column_slice(&[1.0, 10.0, 0.1, 3.0, 1.0]);
        let products: [Box<dyn Fn(&DVector<f64>, &DVector<f64>) -> f64>; 2] = [Box::new(|u, v| u.dot(v)), Box::new(move |u, v| u.component_mul(&weights).dot(&v.component_mul(&weights)))];
        let radius = (DMatrix::identity(5, 5) - lu.solve(&a).unwrap()).complex_eigenvalues().iter().map(|e| e.norm()).fold(0.0, f64::max);
        assert!((0.3..0.9).contains(&radius), "spectral radius {radius}");
        for dot in products {
            let (mut x, mut plain, mut broyden) = (DVector::zeros(5), DVector::zeros(5), Broyden::default());
            for _ in 0..10 {
                x += broyden.step(-lu.solve(&(&a * &x - &b)).unwrap(), &dot);
                plain -= lu.solve(&(&a * &plain - &b)).unwrap();
            }
            let (residual, plain_residual) = ((&a * &x - &b).norm() / b.norm(), (&a * &plain - &b).norm() / b.norm());
            assert!(residual < 1e-10, "Broyden after 2n steps: relative residual {residual}");
            assert!(plain_residual > 1e-4, "modified Newton after 2n steps: {plain_residual}");
            eprintln!("radius {radius:.3}: relative residual after 2n steps {residual:.1e} (Broyden), {plain_residual:.1e} (modified Newton)");
        }
    }

    /// A step along which the update would make B singular restarts from B_0's step.
    #[test]
    fn restarts_when_the_update_is_singular() {
        let mut broyden = Broyden::default();
        let dot = |u: &DVector<f64>, v: &DVector<f64>| u.dot(v);
        let first = broyden.step(DVector::from_column_slice(&[1.0, 0.0]), dot);
        assert_eq!(first.as_slice(), &[1.0, 0.0]);
        // z = s_0: the denominator 1 − ⟨s_0, z⟩/⟨s_0, s_0⟩ is 0.
        let second = broyden.step(DVector::from_column_slice(&[1.0, 0.0]), dot);
        assert_eq!(second.as_slice(), &[1.0, 0.0]);
        assert_eq!(broyden.steps.len(), 1, "the history restarts from the last step");
    }
}
