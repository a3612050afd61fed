//! [`SpanIndex`]: the byte spans of every key and value of a TOML document, to turn serde
//! errors and validation paths into dotted field paths and line numbers.

use std::ops::Range;

use super::{DescriptionError, Result, Violation};

/// Byte spans of every key and value of the document, to turn serde errors and validation
/// paths into dotted field paths and line numbers. Shared by the robot description and the
/// scenario loader, which report errors the same way.
pub(crate) struct SpanIndex<'t> {
    file: String,
    text: &'t str,
    /// Where a reader finds the required fields, quoted in "missing field" errors.
    reference: String,
    /// (dotted path, key span, value span); array elements use the element span for both.
    nodes: Vec<(String, Range<usize>, Range<usize>)>,
}

fn contains(outer: &Range<usize>, inner: &Range<usize>) -> bool {
    outer.start <= inner.start && inner.end <= outer.end && outer.start < outer.end
}

fn shorten(s: &str) -> String {
    let s = s.trim();
    if s.chars().count() > 60 {
        format!("{}...", s.chars().take(57).collect::<String>())
    } else {
        s.to_string()
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
    (line, column)
}

impl<'t> SpanIndex<'t> {
    /// Indexes `text` (read from `file`); `reference` names the file or document that shows
    /// the required fields, for "missing field" errors.
    pub(crate) fn build_for(text: &'t str, file: &str, reference: &str) -> Result<Self> {
        let doc = toml::de::DeTable::parse(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            let mut message = e.message().trim().to_string();
            // The parser does not say which key: the span does.
            if let Some(key) = e.span().and_then(|s| text.get(s)).filter(|k| message == "duplicate key" && !k.trim().is_empty()) {
                message = format!("duplicate key `{}`", shorten(key));
            }
            DescriptionError::Syntax { file: file.to_string(), line, column, message }
        })?;
        let mut index = SpanIndex { file: file.to_string(), text, reference: reference.to_string(), nodes: Vec::new() };
        index.walk_table(doc.get_ref(), "");
        Ok(index)
    }

    /// The file the index was built for (named in errors).
    pub(crate) fn file(&self) -> &str {
        &self.file
    }

    fn walk_table(&mut self, table: &toml::de::DeTable<'_>, prefix: &str) {
        for (k, v) in table.iter() {
            let path = if prefix.is_empty() { k.get_ref().to_string() } else { format!("{prefix}.{}", k.get_ref()) };
            self.nodes.push((path.clone(), k.span(), v.span()));
            self.walk_value(v.get_ref(), &path);
        }
    }

    fn walk_value(&mut self, value: &toml::de::DeValue<'_>, path: &str) {
        match value {
            toml::de::DeValue::Table(t) => self.walk_table(t, path),
            toml::de::DeValue::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    let p = format!("{path}[{i}]");
                    self.nodes.push((p.clone(), e.span(), e.span()));
                    self.walk_value(e.get_ref(), &p);
                }
            }
            _ => {}
        }
    }

    /// The most specific node whose key or value span contains `span`: (path, value span).
    fn node_at(&self, span: &Range<usize>) -> Option<(&str, Range<usize>)> {
        let mut best: Option<(usize, usize, &str, Range<usize>)> = None;
        for (path, key, value) in &self.nodes {
            for s in [key, value] {
                if contains(s, span) {
                    let size = s.end - s.start;
                    let depth = path.len();
                    let better = match &best {
                        None => true,
                        Some((bs, bd, ..)) => size < *bs || (size == *bs && depth > *bd),
                    };
                    if better {
                        best = Some((size, depth, path, value.clone()));
                    }
                }
            }
        }
        best.map(|(_, _, p, v)| (p, v))
    }

    /// Whether the document writes the field (or table, or array element) at `path` itself.
    pub(crate) fn has(&self, path: &str) -> bool {
        self.nodes.iter().any(|(p, ..)| p == path)
    }

    /// Line of the field at `path`, or of its closest enclosing table or array element that is
    /// in the file (a missing field is reported at its table).
    pub(crate) fn line_of(&self, path: &str) -> Option<usize> {
        let mut path = path;
        loop {
            if let Some((_, key, _)) = self.nodes.iter().find(|(p, ..)| p == path) {
                return Some(line_col(self.text, key.start).0);
            }
            let cut = path.rfind(['.', '['])?;
            path = &path[..cut];
        }
    }

    /// An error for the first top-level key that is not among `known` (a struct's fields,
    /// [`super::struct_fields`]): checked before deserializing, so that a misspelt table
    /// (`[giat]`) is reported as unknown rather than as the fields missing from the table it
    /// was meant to be (serde visits the keys in sorted order: `gait` before `giat`).
    pub(crate) fn check_top_level(&self, known: &[&str]) -> Result<()> {
        if known.is_empty() {
            return Ok(()); // not a plain struct (flattened): serde checks the keys itself
        }
        let Some((path, key, value)) = self.nodes.iter().find(|(path, _, _)| !path.contains(['.', '[']) && !known.contains(&path.as_str())) else {
            return Ok(());
        };
        let table = self.text[..key.start].trim_end().ends_with('[') || self.nodes.iter().any(|(p, _, _)| p.starts_with(&format!("{path}.")));
        let (written, problem) = if table { (format!("[{path}]"), "unknown table") } else { (shorten(&self.text[value.clone()]), "unknown field") };
        let expected = known.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ");
        Err(DescriptionError::field_error(&self.file, Some(line_col(self.text, key.start).0), path.clone(), written, problem.to_string(), format!("expected one of {expected}")))
    }

    /// The field error of a failed deserialization: the field from the error's span, and the
    /// value, problem and allowed values from serde's message or from the [`Violation`] of a
    /// bounded field.
    pub(crate) fn serde_error(&self, e: &toml::de::Error) -> DescriptionError {
        let msg = e.message().trim().to_string();
        let span = e.span().filter(|s| s.start < s.end);
        let line = span.as_ref().map(|s| line_col(self.text, s.start).0);
        let field_err = |field: String, value: String, problem: &str, allowed: String| {
            DescriptionError::field_error(&self.file, line, field, value, problem.to_string(), allowed)
        };
        let quoted = |m: &str| m.split('`').nth(1).unwrap_or("").to_string();
        let join = |parent: &str, child: &str| {
            if parent.is_empty() {
                child.to_string()
            } else {
                format!("{parent}.{child}")
            }
        };
        let node = span.as_ref().and_then(|s| self.node_at(s));
        if let Some(v) = Violation::parse(&msg) {
            let path = node.map_or_else(|| "<document>".to_string(), |(p, _)| p.to_string());
            return match v.element {
                Some(i) => {
                    let path = format!("{path}[{i}]");
                    let line = self.line_of(&path).or(line);
                    DescriptionError::field_error(&self.file, line, path, v.value, v.problem, v.allowed)
                }
                None => field_err(path, v.value, &v.problem, v.allowed),
            };
        }
        if msg.starts_with("missing field `") {
            let parent = node.map(|(p, _)| p.to_string()).unwrap_or_default();
            return field_err(
                join(&parent, &quoted(&msg)),
                "<missing>".to_string(),
                "missing field",
                format!("the field is required (see {})", self.reference),
            );
        }
        let expected = msg
            .split_once(", expected ")
            .map(|(_, x)| format!("expected {x}"))
            .or_else(|| msg.split_once(", there are no fields").map(|_| "no fields here".to_string()))
            .unwrap_or_else(|| msg.clone());
        if msg.starts_with("unknown field `") {
            let (path, value) = match node {
                Some((p, v)) => (p.to_string(), shorten(&self.text[v])),
                None => (quoted(&msg), "?".to_string()),
            };
            return field_err(path, value, "unknown field", expected);
        }
        let (path, value) = match (node, span) {
            (Some((p, _)), Some(s)) => (p.to_string(), shorten(&self.text[s])),
            _ => ("<document>".to_string(), "?".to_string()),
        };
        let problem = msg.split(", expected ").next().unwrap_or(&msg).to_string();
        field_err(path, value, &problem, expected)
    }
}
