//! The friction distributions of the Monte Carlo runs (Section 6.5, Table 6.7).

use super::tables::{LoadDependenceTable, MonteCarloTable, RobotDescription};
use super::values::{Gaussian, PerLeg, PerLegMaybe};
use crate::hexapod::PantographJoint;

/// Monte Carlo distributions of the Eq. 5.12 coefficients, computed from Table 5.5 like
/// Table 6.7 was (mean and n-1 standard deviation of the leg means, excluded legs left out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadDependenceDistribution {
    pub a_2_plus: Option<Gaussian>,
    pub a_2_minus: Option<Gaussian>,
    pub a_1_plus: Option<Gaussian>,
    pub a_1_minus: Option<Gaussian>,
}

/// Mean and sample (n-1) standard deviation of the given values, skipping `excluded`
/// indices and missing values; None when fewer than two values remain.
pub fn across_legs(values: &[Option<f64>], excluded: &[usize]) -> Option<Gaussian> {
    let kept: Vec<f64> =
        values.iter().enumerate().filter(|(i, _)| !excluded.contains(i)).filter_map(|(_, v)| *v).collect();
    if kept.len() < 2 {
        return None;
    }
    let n = kept.len() as f64;
    let mu = kept.iter().sum::<f64>() / n;
    let var = kept.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (n - 1.0);
    Some(Gaussian { mu, sigma: var.sqrt() })
}

impl MonteCarloTable {
    /// Distributions of a_2^+-, a_1^+- for the Monte Carlo runs with load influence
    /// (Section 6.5: "the same process is performed on polynomial coefficients").
    pub fn load_dependence_distribution(&self, table: &LoadDependenceTable) -> LoadDependenceDistribution {
        let plain = |p: &PerLeg| p.mu.iter().map(|&v| Some(v)).collect::<Vec<_>>();
        let maybe = |p: &PerLegMaybe| p.mu.iter().map(|v| v.value()).collect::<Vec<_>>();
        LoadDependenceDistribution {
            a_2_plus: across_legs(&plain(&table.a_2_plus_n_per_kg2), &self.excluded_legs_a_2_plus),
            a_2_minus: across_legs(&plain(&table.a_2_minus_n_per_kg2), &self.excluded_legs_a_2_minus),
            a_1_plus: across_legs(&maybe(&table.a_1_plus_n_per_kg), &self.excluded_legs_a_1_plus),
            a_1_minus: across_legs(&maybe(&table.a_1_minus_n_per_kg), &self.excluded_legs_a_1_minus),
        }
    }
}

impl RobotDescription {
    /// Distributions of Table 6.7 for one joint kind, as (tau_f_d^+, f_v^+, tau_f_d^-, f_v^-);
    /// the viscous entries are None for q_h (neglected in Section 6.5).
    pub fn monte_carlo_distribution(&self, joint: PantographJoint) -> (Gaussian, Option<Gaussian>, Gaussian, Option<Gaussian>) {
        let m = &self.monte_carlo;
        match joint {
            PantographJoint::Rotation => (m.q_r.tau_f_d_plus_nm, Some(m.q_r.f_v_plus_nms), m.q_r.tau_f_d_minus_nm, Some(m.q_r.f_v_minus_nms)),
            PantographJoint::Vertical => (
                m.q_v.tau_f_d_plus_n,
                Some(m.q_v.f_v_plus_ns_per_m),
                m.q_v.tau_f_d_minus_n,
                Some(m.q_v.f_v_minus_ns_per_m),
            ),
            PantographJoint::Horizontal => (m.q_h.tau_f_d_plus_n, None, m.q_h.tau_f_d_minus_n, None),
        }
    }
}
