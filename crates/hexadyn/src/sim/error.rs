//! Failures of the solver, reported with the instant, the step and the offending rows.

use std::fmt;

/// One residual row that did not converge, with the element that owns it.
#[derive(Clone, Debug, PartialEq)]
pub struct ResidualRow {
    pub row: usize,
    pub coordinate: String,
    pub element: String,
    pub value: f64,
}

impl fmt::Display for ResidualRow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "row {} ({}, element {}) = {:.3e}", self.row, self.coordinate, self.element, self.value)
    }
}

fn list_rows(r: &[ResidualRow]) -> String {
    r.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("; ")
}

fn step(h: &Option<f64>) -> String {
    h.map(|h| format!(" with the step h = {h:.3e} s")).unwrap_or_default()
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("Newton-Raphson did not converge at t = {t:.6} s with the minimum step h = {h:.3e} s; largest residuals: {}", list_rows(.rows))]
    NewtonDiverged { t: f64, h: f64, rows: Vec<ResidualRow> },
    #[error("the error estimate (Eq. 3.15) stays above tolerance at t = {t:.6} s with the minimum step h = {h:.3e} s (error {error:.3e}); fastest-changing rows: {}", list_rows(.rows))]
    StepTooSmall { t: f64, h: f64, error: f64, rows: Vec<ResidualRow> },
    /// `h` is the step being attempted (None outside a time step: initial accelerations, statics).
    #[error("non-finite residual at t = {t:.6} s{}: {}", step(.h), list_rows(.rows))]
    NonFinite { t: f64, h: Option<f64>, rows: Vec<ResidualRow> },
    #[error("singular {what} matrix at t = {t:.6} s")]
    Singular { what: &'static str, t: f64 },
    #[error("static equilibrium not found after {iterations} iterations; largest residuals: {}", list_rows(.rows))]
    NoEquilibrium { iterations: usize, rows: Vec<ResidualRow> },
    #[error("invalid solver option {field} = {value}: {allowed}")]
    InvalidOption { field: &'static str, value: f64, allowed: &'static str },
    #[error("cannot integrate backwards: requested t = {requested} s < current t = {current} s")]
    Backwards { requested: f64, current: f64 },
}

/// The `count` largest |f_i| with their names, for error messages.
pub(crate) fn largest_rows(layout: &super::Layout, f: &[f64], count: usize) -> Vec<ResidualRow> {
    let mut idx: Vec<usize> = (0..f.len()).collect();
    let key = |i: usize| if f[i].is_finite() { f[i].abs() } else { f64::INFINITY };
    idx.sort_by(|&a, &b| key(b).total_cmp(&key(a)));
    idx.into_iter()
        .take(count)
        .map(|i| ResidualRow {
            row: i,
            coordinate: layout.names.get(i).cloned().unwrap_or_default(),
            element: layout.elements.get(i).cloned().unwrap_or_default(),
            value: f[i],
        })
        .collect()
}
