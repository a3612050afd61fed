//! `extends = "<shipped robot>"`: a pantograph description written as the changes to a shipped
//! one (a drive variant of AMRU5 changes its reductions, motor and friction referral and keeps
//! every other table). The base's tables are taken and the file's merged over them key by key:
//! a table merges into the base's table of the same name, any other value (numbers, strings,
//! arrays, arrays of tables such as `[[legs]]`) replaces the base's. The result is read and
//! validated like any description; its errors name the file, and the line of the field when the
//! file writes it, else say that the field comes from the base.

use super::SHIPPED_ROBOTS;
use crate::fields::{DescriptionError, Result, SpanIndex};

/// The top-level key naming the base.
pub(super) const KEY: &str = "extends";

/// The description's text with its base merged under it, and the base's name; None when the
/// text extends nothing. A base that extends another is merged with it first.
pub(super) fn merged(text: &str, index: &SpanIndex) -> Result<Option<(String, &'static str)>> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| index.serde_error(&e))?;
    let Some(base) = table.remove(KEY) else { return Ok(None) };
    let pantograph = |text: &str| toml::from_str::<toml::Table>(text).is_ok_and(|t| !t.contains_key("leg_mechanism"));
    let pantographs: Vec<&(&str, &str, &str)> = SHIPPED_ROBOTS.iter().filter(|(_, text, _)| pantograph(text)).collect();
    let allowed = || format!("the name of a shipped pantograph robot ({})", pantographs.iter().map(|(name, _, _)| format!("\"{name}\"")).collect::<Vec<_>>().join(", "));
    let Some((name, base_text, base_origin)) = base.as_str().and_then(|b| pantographs.iter().find(|(name, _, _)| *name == b)).copied() else {
        let line = index.line_of(KEY);
        return Err(DescriptionError::field_error(index.file(), line, KEY.to_string(), base.to_string(), "not a shipped pantograph robot".to_string(), allowed()));
    };
    let base_index = SpanIndex::build_for(base_text, base_origin, "")?;
    let base_text = merged(base_text, &base_index)?.map_or_else(|| base_text.to_string(), |(t, _)| t);
    let mut base_table: toml::Table = toml::from_str(&base_text).map_err(|e| base_index.serde_error(&e))?;
    merge(&mut base_table, table);
    Ok(Some((base_table.to_string(), name)))
}

/// `over` merged into `base`: tables key by key, every other value replaced.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// An error of the merged description, located in the file: the line of the field when the
/// file writes it; otherwise no line, and the field is said to come from the base.
pub(super) fn locate(e: DescriptionError, index: &SpanIndex, base: &str) -> DescriptionError {
    match e {
        DescriptionError::Field(mut f) => {
            if index.has(&f.field) {
                f.line = index.line_of(&f.field);
            } else {
                f.line = None;
                f.problem = format!("{} (a field of the base robot \"{base}\")", f.problem);
            }
            DescriptionError::Field(f)
        }
        other => other,
    }
}
