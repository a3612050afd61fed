//! Scenario overrides: fields of a scenario file changed from outside the file, by dotted
//! field name (`model.friction = "dry_viscous"`, `gait.heading.vx_m_s = 0.01`). The friction
//! comparison and the Monte Carlo campaigns run one scenario file under many overrides.
//!
//! The overrides are written into the parsed file and the result is validated like any file;
//! the scenario then carries the effective text (comments dropped, a header listing the
//! overrides), so a results folder always holds the scenario that actually ran.

use super::{ScenarioError, REFERENCE};
use crate::fields::{FieldError, SpanIndex};

/// One field set from outside the scenario file.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// Dotted field path, e.g. `model.joint_friction.q_r.tau_f_d_plus`.
    pub field: String,
    pub value: toml::Value,
}

impl Override {
    pub fn new(field: impl Into<String>, value: impl Into<toml::Value>) -> Self {
        Override { field: field.into(), value: value.into() }
    }
}

fn field_error(origin: &str, field: &str, value: &toml::Value, problem: &str, allowed: &str) -> ScenarioError {
    ScenarioError::Field(Box::new(FieldError {
        file: origin.to_string(),
        line: None,
        field: field.to_string(),
        value: value.to_string(),
        problem: format!("override: {problem}"),
        allowed: allowed.to_string(),
    }))
}

/// The scenario text with `overrides` applied, in order. Tables on the path are created as
/// needed; a path through a value that is not a table (`scenario.name.x`) or into an array of
/// tables is an error naming the override. Field names themselves are checked by the scenario
/// validation that follows.
pub(super) fn apply(text: &str, origin: &str, overrides: &[Override]) -> Result<String, ScenarioError> {
    // Syntax errors of the file itself are reported with their line, as without overrides.
    SpanIndex::build_for(text, origin, REFERENCE).map_err(ScenarioError::from_parse)?;
    let mut doc: toml::Table = toml::from_str(text).map_err(|e| ScenarioError::Io { file: origin.to_string(), reason: e.to_string() })?;
    for o in overrides {
        let parts: Vec<&str> = o.field.split('.').collect();
        if parts.iter().any(|p| p.trim().is_empty()) {
            return Err(field_error(origin, &o.field, &o.value, "not a field path", &format!("a dotted field path such as model.friction (see {REFERENCE})")));
        }
        let (last, parents) = parts.split_last().expect("split yields at least one part");
        let mut table = &mut doc;
        for (depth, part) in parents.iter().enumerate() {
            let entry = table.entry(part.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
            table = match entry {
                toml::Value::Table(t) => t,
                _ => {
                    let at = parts[..=depth].join(".");
                    return Err(field_error(origin, &o.field, &o.value, &format!("{at} is not a table"), "a path through tables only (entries of arrays such as control.motion cannot be overridden)"));
                }
            };
        }
        table.insert(last.to_string(), o.value.clone());
    }
    // One comment line per override, whatever its text holds (a newline would end the comment).
    let listed: Vec<String> = overrides.iter().map(|o| format!("#   {} = {}", o.field, o.value).replace(['\n', '\r'], " ")).collect();
    let body = toml::to_string(&doc).map_err(|e| ScenarioError::Io { file: origin.to_string(), reason: format!("cannot write the overridden scenario: {e}") })?;
    Ok(format!("# {origin} with overrides:\n{}\n{body}", listed.join("\n")))
}

/// An error of the overridden scenario: its line numbers are those of the effective text, not
/// of the file, so they are dropped; a field set by an override says so.
pub(super) fn locate(e: ScenarioError, overrides: &[Override]) -> ScenarioError {
    match e {
        ScenarioError::Field(mut f) => {
            f.line = None;
            let set_by = overrides.iter().find(|o| f.field == o.field || f.field.starts_with(&format!("{}.", o.field)));
            if let Some(o) = set_by {
                f.problem = format!("{} (set by the override {})", f.problem, o.field);
            }
            ScenarioError::Field(f)
        }
        other => other,
    }
}
