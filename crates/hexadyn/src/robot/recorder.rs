//! Time series recorded during a run: one row per control instant, named columns with units.
//!
//! A [`Recorder`] fills a [`TimeSeries`] row by row. The first row defines the columns (name,
//! unit, description); every later row must put the same columns in the same order, which
//! [`Recorder::end_row`] checks. The names follow the thesis symbols with the joint or foot
//! index in brackets: `q_v[2]`, `i_q_v[2]`, `tau_f_q_v[2]`, `Fz[2]` (see [`super::columns`]
//! for the full list).

use std::fmt;

/// One named column of a [`TimeSeries`].
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// Column name, e.g. `q_v[2]`.
    pub name: String,
    /// SI unit, e.g. `m`, `rad/s`, `N`, `J` (`1` for dimensionless).
    pub unit: &'static str,
    /// One line saying what the column holds.
    pub description: String,
    pub values: Vec<f64>,
}

/// Columns of equal length sampled at the same instants (the first column is usually `t`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TimeSeries {
    pub columns: Vec<Column>,
}

impl TimeSeries {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    /// The values of a column.
    pub fn values(&self, name: &str) -> Option<&[f64]> {
        self.column(name).map(|c| c.values.as_slice())
    }

    /// The unit of a column.
    pub fn unit(&self, name: &str) -> Option<&'static str> {
        self.column(name).map(|c| c.unit)
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.columns.iter().map(|c| c.name.as_str())
    }
}

/// Recorded a row with a different set of columns than the first row.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RowMismatch {
    pub row: usize,
    pub expected: usize,
    pub got: usize,
}

impl fmt::Display for RowMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "row {} has {} values, the first row defined {} columns", self.row, self.got, self.expected)
    }
}

/// Fills a [`TimeSeries`] one row at a time.
///
/// ```
/// use hexadyn::robot::recorder::Recorder;
/// let mut rec = Recorder::default();
/// for k in 0..3 {
///     rec.begin_row();
///     rec.put(0.01 * k as f64, || ("t".into(), "s", "time".into()));
///     rec.put(2.0 * k as f64, || ("x".into(), "m", "a position".into()));
///     rec.end_row();
/// }
/// let series = rec.finish();
/// assert_eq!(series.len(), 3);
/// assert_eq!(series.values("x"), Some(&[0.0, 2.0, 4.0][..]));
/// ```
///
/// A long run is handed out in chunks ([`Recorder::take_chunk`]):
///
/// ```
/// use hexadyn::robot::recorder::Recorder;
/// let mut rec = Recorder::default();
/// let mut chunks = Vec::new();
/// for k in 0..5 {
///     rec.begin_row();
///     rec.put(k as f64, || ("t".into(), "s", "time".into()));
///     rec.end_row();
///     if rec.buffered() == 2 {
///         chunks.push(rec.take_chunk());
///     }
/// }
/// chunks.push(rec.take_chunk());
/// let lengths: Vec<usize> = chunks.iter().map(|c| c.len()).collect();
/// assert_eq!(lengths, [2, 2, 1]);
/// assert_eq!(chunks[2].values("t"), Some(&[4.0][..]));
/// assert_eq!(rec.rows(), 5);
/// ```
#[derive(Clone, Debug, Default)]
pub struct Recorder {
    /// The columns, defined by the first row; their values are handed out by
    /// [`Recorder::take_chunk`] and [`Recorder::finish`].
    columns: Vec<Column>,
    /// The values of the rows since the last chunk, row after row: one push per value instead of
    /// one into each column's vector (a row of the validation walk has about 300 values),
    /// transposed into the columns when handed out.
    values: Vec<f64>,
    rows: usize,
    cursor: usize,
}

impl Recorder {
    pub fn begin_row(&mut self) {
        self.cursor = 0;
    }

    /// Puts the next value of the row. `spec` (name, unit, description) is called on the first
    /// row only, where it defines the column.
    pub fn put(&mut self, value: f64, spec: impl FnOnce() -> (String, &'static str, String)) {
        if self.rows == 0 {
            let (name, unit, description) = spec();
            debug_assert!(self.columns.iter().all(|c| c.name != name), "duplicate column {name}");
            self.columns.push(Column { name, unit, description, values: Vec::new() });
        }
        if self.cursor < self.columns.len() {
            self.values.push(value);
        }
        self.cursor += 1;
    }

    /// Puts `values` as the next values of the row, `spec(k)` defining the column of `values[k]`
    /// on the first row: after it one copy of the slice instead of a [`Self::put`] per value.
    pub fn put_each(&mut self, values: &[f64], spec: impl Fn(usize) -> (String, &'static str, String)) {
        if self.rows == 0 {
            for (k, &value) in values.iter().enumerate() {
                self.put(value, || spec(k));
            }
            return;
        }
        let kept = self.columns.len().saturating_sub(self.cursor).min(values.len());
        self.values.extend_from_slice(&values[..kept]);
        self.cursor += values.len();
    }

    /// Closes the row.
    ///
    /// # Panics
    /// If the row did not put exactly the columns of the first row (a bug of the caller).
    pub fn end_row(&mut self) {
        let expected = self.columns.len();
        if self.cursor != expected {
            panic!("{}", RowMismatch { row: self.rows, expected, got: self.cursor });
        }
        self.rows += 1;
    }

    /// Rows recorded so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The rows recorded so far as a time series.
    pub fn finish(mut self) -> TimeSeries {
        self.take_chunk()
    }

    /// Rows recorded since the last [`Recorder::take_chunk`] (or the start).
    pub fn buffered(&self) -> usize {
        self.values.len().checked_div(self.columns.len()).unwrap_or(0)
    }

    /// Takes the rows recorded since the last call (the columns with their values so far) and
    /// goes on recording into empty columns: a long run handed out in chunks holds one chunk at
    /// a time.
    pub fn take_chunk(&mut self) -> TimeSeries {
        let width = self.columns.len();
        // Column k is every width-th value from k: read in order of the columns, the rows of
        // eight neighbouring columns share their cache lines.
        let values = &self.values;
        let columns = self.columns.iter().enumerate().map(|(k, c)| Column { name: c.name.clone(), unit: c.unit, description: c.description.clone(), values: values.iter().skip(k).step_by(width).copied().collect() }).collect();
        self.values.clear();
        TimeSeries { columns }
    }
}
