//! Fields of the TOML input files (the robot description, [`crate::description`], and the
//! scenario files, [`crate::scenario`]): where each field stands in the file, how a bad field
//! is reported, and the bounds a single field declares.
//!
//! Every error names the file, the line when it is known, the dotted field path, the value as
//! read and what is allowed:
//!
//! ```text
//! robots/amru5.toml:179: field `motor.resistance_ohm` = -0.334: out of range; allowed: a finite number > 0
//! ```
//!
//! A field whose constraint involves only itself declares it with its type in the file mirror,
//! `#[serde(deserialize_with = "Positive::checked")]`, and is checked while deserializing
//! (`Bound`); the span index turns that error into the line and path of the field
//! (`SpanIndex::serde_error`). Relations between fields are checked after deserializing with
//! a `Ctx`, which names the field path itself.

use std::fmt;

mod bounded;
mod csv_records;
mod span_index;

pub(crate) use bounded::{bounds, seq, Bound, Finite, NonNegative, Positive, Value, Violation};
pub(crate) use csv_records::csv_records;
pub(crate) use span_index::SpanIndex;

/// The largest text input file read (scenario, robot description, heading and height CSV, link configuration):
/// 64 MB, far above any real one (kilobytes; a 1000 s heading series at 100 Hz is 4 MB), so
/// that naming a device (`/dev/zero`) or a huge file fails at once instead of filling memory.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// The largest terrain mesh file read: 1 GB (an ASCII PLY at the bounds of a mesh,
/// [`crate::physics::terrain::ply::MAX_MESH_TRIANGLES`], with a few extra properties).
pub const MAX_MESH_BYTES: u64 = 1 << 30;

/// Opens an input file for reading: a regular file of at most `limit` bytes, refused at once
/// otherwise, with a one-line reason naming what it is (a directory, a named pipe, a device, a
/// socket) and what is allowed. The type and size are checked before the file is opened, and
/// again on the open file: the open itself does not block (`O_NONBLOCK`), so a path swapped for
/// a named pipe in between is refused too instead of waiting for a writer. Returns the file
/// and its size.
pub fn open_input(path: impl AsRef<std::path::Path>, limit: u64) -> std::result::Result<(std::fs::File, u64), String> {
    let path = path.as_ref();
    let checked = |meta: std::fs::Metadata| -> std::result::Result<u64, String> {
        let allowed = format!("allowed: a regular file of at most {}", bytes_shown(limit));
        if !meta.is_file() {
            return Err(format!("{}; {allowed}", file_kind(&meta.file_type())));
        }
        if meta.len() > limit {
            return Err(format!("{} bytes, too large; {allowed}", meta.len()));
        }
        Ok(meta.len())
    };
    checked(std::fs::metadata(path).map_err(|e| e.to_string())?)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path).map_err(|e| e.to_string())?;
    let size = checked(file.metadata().map_err(|e| e.to_string())?)?;
    Ok((file, size))
}

/// What a file that is not a regular file is, for [`open_input`]'s refusal.
fn file_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a named pipe (FIFO), not a regular file";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device, not a regular file";
        }
        if kind.is_socket() {
            return "a socket, not a regular file";
        }
    }
    if kind.is_dir() {
        "a directory, not a file"
    } else {
        "not a regular file"
    }
}

/// A size limit in bytes as people read it (`64 MB`, `1 GB`: binary multiples).
fn bytes_shown(n: u64) -> String {
    match n {
        n if n >= 1 << 30 && n % (1 << 30) == 0 => format!("{} GB", n >> 30),
        n if n >= 1 << 20 && n % (1 << 20) == 0 => format!("{} MB", n >> 20),
        n => format!("{n} bytes"),
    }
}

/// Reads an input file's bytes: a regular file of at most `limit` bytes ([`open_input`]), so
/// that naming a device (`/dev/zero`), a named pipe or a huge file fails at once instead of
/// blocking or filling memory. The error is a one-line reason.
pub fn read_input_bytes(path: impl AsRef<std::path::Path>, limit: u64) -> std::result::Result<Vec<u8>, String> {
    use std::io::Read;
    let (file, size) = open_input(path, limit)?;
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(format!("grew past {} while read; allowed: a regular file of at most {}", bytes_shown(limit), bytes_shown(limit)));
    }
    Ok(bytes)
}

/// Reads an input file as text: a regular file of at most [`MAX_INPUT_BYTES`]
/// ([`read_input_bytes`]), in UTF-8. The error is a one-line reason.
pub fn read_input(path: impl AsRef<std::path::Path>) -> std::result::Result<String, String> {
    let bytes = read_input_bytes(path, MAX_INPUT_BYTES)?;
    String::from_utf8(bytes).map_err(|e| format!("not UTF-8 text (invalid byte at offset {})", e.utf8_error().valid_up_to()))
}

/// The field names a serde-derived struct accepts (those its `Deserialize` passes to
/// `deserialize_struct`), so that keys can be checked before values ([`SpanIndex::check_top_level`]).
pub(crate) fn struct_fields<'de, T: serde::Deserialize<'de>>() -> &'static [&'static str] {
    use serde::de::{self, Visitor};
    struct Probe<'a>(&'a mut &'static [&'static str]);
    impl<'de> serde::Deserializer<'de> for Probe<'_> {
        type Error = de::value::Error;
        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> std::result::Result<V::Value, Self::Error> {
            Err(de::Error::custom("not a struct"))
        }
        fn deserialize_struct<V: Visitor<'de>>(self, _: &'static str, fields: &'static [&'static str], _: V) -> std::result::Result<V::Value, Self::Error> {
            *self.0 = fields;
            Err(de::Error::custom("probed"))
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option unit unit_struct
            newtype_struct seq tuple tuple_struct map enum identifier ignored_any
        }
    }
    let mut fields: &'static [&'static str] = &[];
    let _ = T::deserialize(Probe(&mut fields));
    fields
}

/// An input file (robot description or scenario) that could not be read, parsed or validated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    /// The file could not be read.
    #[error("{file}: cannot read the robot description: {reason}")]
    Io { file: String, reason: String },
    /// The text is not valid TOML.
    #[error("{file}:{line}:{column}: TOML syntax error: {message}")]
    Syntax { file: String, line: usize, column: usize, message: String },
    /// A field is missing, unknown, of the wrong type or out of its allowed range.
    #[error("{0}")]
    Field(Box<FieldError>),
}

/// The details of a [`DescriptionError::Field`].
#[derive(Clone, Debug, PartialEq)]
pub struct FieldError {
    pub file: String,
    /// 1-based line of the field in the file, when known.
    pub line: Option<usize>,
    /// Dotted path, e.g. `motor.resistance_ohm` or `legs[2].angle_deg`.
    pub field: String,
    /// The offending value as written (or `<missing>`).
    pub value: String,
    /// What is wrong (`out of range`, `unknown field`, `missing field`, `invalid type`...).
    pub problem: String,
    /// What would be accepted.
    pub allowed: String,
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        write!(f, ": field `{}` = {}: {}; allowed: {}", self.field, self.value, self.problem, self.allowed)
    }
}

impl DescriptionError {
    pub(crate) fn field_error(
        file: &str,
        line: Option<usize>,
        field: String,
        value: String,
        problem: String,
        allowed: String,
    ) -> Self {
        DescriptionError::Field(Box::new(FieldError { file: file.to_string(), line, field, value, problem, allowed }))
    }

    /// The file (or origin name) the error refers to.
    pub fn file(&self) -> &str {
        match self {
            DescriptionError::Io { file, .. } | DescriptionError::Syntax { file, .. } => file,
            DescriptionError::Field(e) => &e.file,
        }
    }

    /// The dotted field path, for field errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            DescriptionError::Field(e) => Some(&e.field),
            _ => None,
        }
    }
}

pub(crate) type Result<T> = std::result::Result<T, DescriptionError>;

/// The checks of one file after deserializing: errors name `file` and, with an index, the line
/// of the field.
pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
    pub(crate) index: Option<&'a SpanIndex<'a>>,
}

impl Ctx<'_> {
    /// The error of the field at the dotted path `field`.
    pub(crate) fn err(&self, field: &str, value: impl fmt::Display, problem: &str, allowed: impl Into<String>) -> DescriptionError {
        DescriptionError::field_error(
            self.file,
            self.index.and_then(|i| i.line_of(field)),
            field.to_string(),
            value.to_string(),
            problem.to_string(),
            allowed.into(),
        )
    }

    /// `ok` for a finite `value`: "not a finite number" or "out of range" otherwise.
    pub(crate) fn check(&self, ok: bool, field: &str, value: f64, allowed: &str) -> Result<()> {
        if !value.is_finite() {
            return Err(self.err(field, value, "not a finite number", allowed));
        }
        if ok {
            Ok(())
        } else {
            Err(self.err(field, value, "out of range", allowed))
        }
    }

    /// `value` within the bound `B`, with the error a bounded field of the file gets.
    pub(crate) fn bounded<B: Bound>(&self, field: &str, value: f64) -> Result<()> {
        self.check(B::holds(value), field, value, B::ALLOWED)
    }

    pub(crate) fn finite(&self, field: &str, v: f64) -> Result<()> {
        self.bounded::<Finite>(field, v)
    }

    pub(crate) fn positive(&self, field: &str, v: f64) -> Result<()> {
        self.bounded::<Positive>(field, v)
    }

    pub(crate) fn non_negative(&self, field: &str, v: f64) -> Result<()> {
        self.bounded::<NonNegative>(field, v)
    }
}
