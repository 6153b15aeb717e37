//! Reader and writer for the measured-data format, version 1 (`DATA.md`).
//!
//! A dataset is a directory holding `dataset.toml` and the CSV series files it
//! names, with paths relative to the directory. [`load()`] reads and validates
//! one; [`write()`] creates a new one and never overwrites existing files.
//!
//! Every error names the file it is about, and the line where there is one.
//! Recoverable problems (unknown keys, skipped CSV rows) do not fail the load;
//! they are collected in [`Dataset::warnings`] as `"FILE:LINE: reason"`.
#![deny(missing_docs)]

use std::cell::OnceCell;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::fs;
use std::io;
use std::marker::PhantomData;
use std::ops::Range;
use std::path::{Component, Path, PathBuf};

use serde::de::value::MapAccessDeserializer;
use serde::de::{Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use toml::{Spanned, Value};

/// The format version this module reads and writes.
pub const FORMAT_VERSION: i64 = 1;

/// File name of the manifest inside a dataset directory.
pub const MANIFEST_FILE: &str = "dataset.toml";

/// Largest share of bad data rows, in percent, a series file may have.
pub const MAX_BAD_ROWS_PERCENT: usize = 5;

// ---------------------------------------------------------------------------
// Public data model
// ---------------------------------------------------------------------------

/// A measured dataset: the contents of `dataset.toml` and its series files.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    /// Directory the dataset was loaded from; series paths are relative to it.
    /// [`write()`] ignores it and writes to the directory it is given.
    pub dir: PathBuf,
    /// Name of the dataset (`name`).
    pub name: String,
    /// Free-text origin of the data (`source`), if given.
    pub source: Option<String>,
    /// The measured belt (`[belt]`).
    pub belt: BeltSpec,
    /// Static tests: belt ring settled on a flat floor (`[[static]]`).
    pub statics: Vec<StaticEntry>,
    /// Dynamic tests: roller put on the top point A (`[[dynamic]]`).
    pub dynamics: Vec<DynamicEntry>,
    /// Scroll tests: belt turned between two wheels (`[[scroll]]`).
    pub scrolls: Vec<ScrollEntry>,
    /// Problems that did not stop the load, e.g. skipped CSV rows or unknown
    /// keys, each as `"FILE:LINE: reason"`. Not written by [`write()`].
    pub warnings: Vec<String>,
}

/// The measured belt (`[belt]`).
#[derive(Debug, Clone, PartialEq)]
pub struct BeltSpec {
    /// Total length of the closed belt loop, mm.
    pub length_mm: f64,
    /// Belt width, mm.
    pub width_mm: f64,
    /// Belt thickness, mm.
    pub thickness_mm: f64,
    /// Belt mass, kg.
    pub mass_kg: f64,
    /// Number of grousers, if given.
    pub grousers: Option<u32>,
    /// Grouser pitch, mm, if given.
    pub grouser_pitch_mm: Option<f64>,
}

impl BeltSpec {
    /// The model's belt (SI units) with `links` links.
    pub fn belt(&self, links: usize) -> trackbelt::params::Belt<f64> {
        trackbelt::params::Belt {
            length_m: self.length_mm * 1e-3,
            width_m: self.width_mm * 1e-3,
            thickness_m: self.thickness_mm * 1e-3,
            mass_kg: self.mass_kg,
            links,
        }
    }
}

/// One static test (`[[static]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticEntry {
    /// Free-text label of the run, if given.
    pub label: Option<String>,
    /// Height of the top point A above the floor, mm.
    pub hs_mm: f64,
    /// Overall width of the settled ring, mm.
    pub ws_mm: f64,
}

/// One dynamic test (`[[dynamic]]`): a roller put on the top point A.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicEntry {
    /// Free-text label of the run, if given.
    pub label: Option<String>,
    /// Mass of the roller, kg.
    pub roller_kg: f64,
    /// Measured height of A with the roller on it, mm.
    pub hd_mm: Option<f64>,
    /// Measured overall width with the roller on it, mm.
    pub wd_mm: Option<f64>,
    /// Measured oscillation period, s.
    pub period_s: Option<f64>,
    /// Measured logarithmic decrement, `ln(A_n / A_n+1)`.
    pub log_decrement: Option<f64>,
    /// Height of A before the roller was put on, mm.
    pub settled_hs_mm: Option<f64>,
    /// Time series of the test, if one was recorded.
    pub series: Option<DynamicSeries>,
}

/// Time series of a dynamic test (CSV columns `t_s,a_height_mm[,a_x_mm]`).
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicSeries {
    /// The CSV file as named in `dataset.toml`, relative to [`Dataset::dir`].
    pub file: PathBuf,
    /// Time since the roller was released, s; strictly increasing.
    pub t_s: Vec<f64>,
    /// Height of A above the floor, mm; one value per time.
    pub a_height_mm: Vec<f64>,
    /// Horizontal position of A, mm, if the file has that column.
    pub a_x_mm: Option<Vec<f64>>,
}

/// One scroll test (`[[scroll]]`): belt turned between two wheels.
#[derive(Debug, Clone, PartialEq)]
pub struct ScrollEntry {
    /// Free-text label of the run, if given.
    pub label: Option<String>,
    /// Drive wheel diameter, mm.
    pub drive_diameter_mm: f64,
    /// Idler wheel diameter, mm.
    pub idler_diameter_mm: f64,
    /// Nominal axle-to-axle distance, mm.
    pub center_distance_mm: f64,
    /// Tensioner force pulling the idler away from the drive, N, if given.
    pub idler_force_n: Option<f64>,
    /// Time series of the test.
    pub series: ScrollSeries,
}

/// Time series of a scroll test
/// (CSV columns `t_s,omega_rad_s,torque_nm[,belt_temp_c]`).
#[derive(Debug, Clone, PartialEq)]
pub struct ScrollSeries {
    /// The CSV file as named in `dataset.toml`, relative to [`Dataset::dir`].
    pub file: PathBuf,
    /// Time, s; strictly increasing.
    pub t_s: Vec<f64>,
    /// Angular speed of the drive wheel, rad/s; one value per time.
    pub omega_rad_s: Vec<f64>,
    /// Drive torque needed to turn the belt, N·m; one value per time.
    pub torque_nm: Vec<f64>,
    /// Belt surface temperature, °C, if the file has that column.
    pub belt_temp_c: Option<Vec<f64>>,
}

/// Mean of one figure over the entries that have it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mean {
    /// The arithmetic mean.
    pub value: f64,
    /// How many entries had the figure.
    pub count: usize,
}

impl Mean {
    /// Mean of `values`, or `None` when there are none.
    fn of(values: impl Iterator<Item = f64>) -> Option<Self> {
        let (sum, count) = values.fold((0.0, 0_usize), |(sum, n), v| (sum + v, n + 1));
        (count > 0).then(|| Self {
            value: sum / count as f64,
            count,
        })
    }
}

/// Means of the optional summary figures of the dynamic tests; a field is
/// `None` when no entry has that figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicMeans {
    /// Mean of `hd_mm`.
    pub hd_mm: Option<Mean>,
    /// Mean of `wd_mm`.
    pub wd_mm: Option<Mean>,
    /// Mean of `period_s`.
    pub period_s: Option<Mean>,
    /// Mean of `log_decrement`.
    pub log_decrement: Option<Mean>,
    /// Mean of `settled_hs_mm`.
    pub settled_hs_mm: Option<Mean>,
}

impl Dataset {
    /// Means of `hs_mm` and `ws_mm` over the static tests, as `(hs, ws)`;
    /// `None` when there is no static test.
    pub fn static_mean(&self) -> Option<(f64, f64)> {
        let hs = Mean::of(self.statics.iter().map(|s| s.hs_mm))?;
        let ws = Mean::of(self.statics.iter().map(|s| s.ws_mm))?;
        Some((hs.value, ws.value))
    }

    /// Mean of each optional summary figure of the dynamic tests over the
    /// entries that have it, with the number of those entries.
    pub fn dynamic_means(&self) -> DynamicMeans {
        let mean = |figure: fn(&DynamicEntry) -> Option<f64>| {
            Mean::of(self.dynamics.iter().filter_map(figure))
        };
        DynamicMeans {
            hd_mm: mean(|e| e.hd_mm),
            wd_mm: mean(|e| e.wd_mm),
            period_s: mean(|e| e.period_s),
            log_decrement: mean(|e| e.log_decrement),
            settled_hs_mm: mean(|e| e.settled_hs_mm),
        }
    }
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

/// Why a dataset could not be loaded or written.
#[derive(Debug)]
#[non_exhaustive]
pub enum DatasetError {
    /// A file or directory could not be read, written or created.
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What was being done, e.g. `"read the manifest"`.
        action: &'static str,
        /// The underlying error.
        source: io::Error,
    },
    /// `dataset.toml` is not valid TOML, lacks a required value, or has a
    /// value of the wrong type or out of range.
    Manifest {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line of the problem, if it has one.
        line: Option<usize>,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The dataset has no `[[static]]`, `[[dynamic]]` or `[[scroll]]` entry.
    EmptyDataset {
        /// The manifest file.
        path: PathBuf,
        /// Last line of the manifest (where an entry would go).
        line: usize,
    },
    /// A series file named in `dataset.toml` does not exist.
    MissingSeries {
        /// The series file that was looked for.
        path: PathBuf,
        /// The manifest naming it.
        manifest: PathBuf,
        /// 1-based line of the `series` key in the manifest.
        line: usize,
    },
    /// A series CSV file is unusable: missing column, no data rows, time not
    /// strictly increasing, or (when writing) inconsistent columns.
    Series {
        /// The series file.
        path: PathBuf,
        /// 1-based line of the problem (the header is line 1), if it has one.
        line: Option<usize>,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// More than [`MAX_BAD_ROWS_PERCENT`] % of a series file's data rows are bad.
    TooManyBadRows {
        /// The series file.
        path: PathBuf,
        /// Number of bad data rows.
        bad: usize,
        /// Number of data rows (header excluded).
        rows: usize,
        /// The first bad row, as `"line N: reason"`.
        first: String,
    },
    /// [`write()`] refused to overwrite an existing file.
    AlreadyExists {
        /// The existing file.
        path: PathBuf,
    },
}

impl fmt::Display for DatasetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io {
                path,
                action,
                source,
            } => write!(f, "{}: cannot {action}: {source}", path.display()),
            Self::Manifest {
                path,
                line,
                message,
            }
            | Self::Series {
                path,
                line,
                message,
            } => write!(f, "{}: {message}", location(path, *line)),
            Self::EmptyDataset { path, line } => write!(
                f,
                "{}: empty dataset: there is no [[static]], [[dynamic]] or [[scroll]] \
                 entry (the file ends at {}); add at least one",
                path.display(),
                location(path, Some(*line))
            ),
            Self::MissingSeries {
                path,
                manifest,
                line,
            } => write!(
                f,
                "{}: series file not found (named at {}); series paths are relative to \
                 the dataset directory: fix the `series` path or add the file",
                path.display(),
                location(manifest, Some(*line))
            ),
            Self::TooManyBadRows {
                path,
                bad,
                rows,
                first,
            } => write!(
                f,
                "{}: {bad} of {rows} data rows are bad, more than the {MAX_BAD_ROWS_PERCENT} % \
                 allowed (first: {first}); fix or delete the bad rows",
                path.display()
            ),
            Self::AlreadyExists { path } => write!(
                f,
                "{}: already exists; refusing to overwrite it: write the dataset to a new \
                 directory or move the existing file away",
                path.display()
            ),
        }
    }
}

impl std::error::Error for DatasetError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// `path:line` or just `path`.
fn location(path: &Path, line: Option<usize>) -> String {
    match line {
        Some(line) => format!("{}:{line}", path.display()),
        None => path.display().to_string(),
    }
}

/// Maps an I/O error on `path` to [`DatasetError::Io`].
fn io_error(path: &Path, action: &'static str) -> impl FnOnce(io::Error) -> DatasetError {
    let path = path.to_path_buf();
    move |source| DatasetError::Io {
        path,
        action,
        source,
    }
}

// ---------------------------------------------------------------------------
// Value rules shared by the reader and the writer
// ---------------------------------------------------------------------------

/// What a numeric field must satisfy.
#[derive(Debug, Clone, Copy)]
enum Rule {
    /// Finite and greater than 0 (lengths, masses, diameters, periods).
    Positive,
    /// Finite and 0 or more (forces).
    NonNegative,
    /// Finite.
    Finite,
}

impl Rule {
    fn allows(self, value: f64) -> bool {
        value.is_finite()
            && match self {
                Self::Positive => value > 0.0,
                Self::NonNegative => value >= 0.0,
                Self::Finite => true,
            }
    }

    fn describe(self) -> &'static str {
        match self {
            Self::Positive => "a finite number greater than 0",
            Self::NonNegative => "a finite number, 0 or more",
            Self::Finite => "a finite number",
        }
    }

    /// `Err(reason)` when `value` breaks the rule for field `key`.
    fn check(self, key: &str, value: f64) -> Result<(), String> {
        if self.allows(value) {
            Ok(())
        } else {
            Err(format!(
                "`{key}` must be {}, found {value}; correct the value",
                self.describe()
            ))
        }
    }
}

/// Names an entry in messages: `[[static]] entry 3 ("track1-run3")`.
fn entry_name(array: &str, index: usize, label: Option<&str>) -> String {
    match label {
        Some(label) => format!("[[{array}]] entry {} ({label:?})", index + 1),
        None => format!("[[{array}]] entry {}", index + 1),
    }
}

/// A series file's columns: the time column first, then the other required
/// ones, then the optional ones.
struct Columns {
    required: &'static [&'static str],
    optional: &'static [&'static str],
}

/// Name of the time column of every series.
const TIME_COLUMN: &str = "t_s";

const DYNAMIC_COLUMNS: Columns = Columns {
    required: &[TIME_COLUMN, "a_height_mm"],
    optional: &["a_x_mm"],
};

const SCROLL_COLUMNS: Columns = Columns {
    required: &[TIME_COLUMN, "omega_rad_s", "torque_nm"],
    optional: &["belt_temp_c"],
};

/// Checks that `times` (one `(line, t)` per row) strictly increase; `Err`
/// holds the offending line and the reason.
fn check_time_order(times: impl Iterator<Item = (usize, f64)>) -> Result<(), (usize, String)> {
    let mut previous: Option<(usize, f64)> = None;
    for (line, t) in times {
        if let Some((previous_line, previous_t)) = previous {
            if t <= previous_t {
                return Err((
                    line,
                    format!(
                        "`{TIME_COLUMN}` = {t} is not greater than {previous_t} on line \
                         {previous_line}; `{TIME_COLUMN}` must increase strictly from row to \
                         row: sort the rows and remove repeated times"
                    ),
                ));
            }
        }
        previous = Some((line, t));
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// Loading: dataset.toml
// ---------------------------------------------------------------------------

/// Loads and validates the dataset in directory `dir`.
///
/// Reads `dir/dataset.toml` and every series file it names. Unknown keys and
/// unknown CSV columns are accepted; unknown keys and skipped CSV rows are
/// reported in [`Dataset::warnings`].
pub fn load(dir: &Path) -> Result<Dataset, DatasetError> {
    let path = dir.join(MANIFEST_FILE);
    let text = fs::read_to_string(&path).map_err(io_error(&path, "read the dataset manifest"))?;
    let doc = Doc::new(&path, &text);
    doc.check_format()?;
    let mut unknown = Vec::new();
    let raw: RawManifest = serde_ignored::deserialize(
        toml::Deserializer::new(&text),
        |key: serde_ignored::Path| {
            unknown.push(KeyPath::of(&key));
        },
    )
    .map_err(|e| doc.toml_error(&e))?;
    let mut loader = Loader {
        doc: &doc,
        dir,
        warnings: doc.unknown_key_warnings(&unknown),
    };
    loader.dataset(&raw)
}

/// The text of a manifest and where it came from.
struct Doc<'a> {
    path: &'a Path,
    text: &'a str,
    /// The manifest parsed again, keeping the place of every key; made on
    /// first use (a key's place is needed only for unknown keys and for
    /// missing keys in `[belt]`), `None` if the text does not parse.
    keys: OnceCell<Option<toml_edit::ImDocument<&'a str>>>,
}

impl<'a> Doc<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        Self {
            path,
            text,
            keys: OnceCell::new(),
        }
    }

    /// 1-based line holding byte `offset`.
    fn line(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        1 + self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
    }

    fn error(&self, span: Option<Range<usize>>, message: impl Into<String>) -> DatasetError {
        DatasetError::Manifest {
            path: self.path.to_path_buf(),
            line: span.map(|span| self.line(span.start)),
            message: message.into(),
        }
    }

    /// Maps a TOML syntax or structure error, keeping its position.
    fn toml_error(&self, error: &toml::de::Error) -> DatasetError {
        let message = error.message().trim().replace('\n', "; ");
        self.error(
            error.span(),
            format!("{message} (dataset.toml must be TOML laid out as in DATA.md)"),
        )
    }

    /// Checks `format` before anything else, so a newer format is reported as
    /// such and not as a pile of layout errors.
    fn check_format(&self) -> Result<(), DatasetError> {
        let probe: FormatProbe = toml::from_str(self.text).map_err(|e| self.toml_error(&e))?;
        let Some(format) = probe.format else {
            return Err(self.error(
                None,
                format!("missing `format`; add `format = {FORMAT_VERSION}` at the top"),
            ));
        };
        match format.get_ref() {
            Value::Integer(FORMAT_VERSION) => Ok(()),
            Value::Integer(other) => Err(self.error(
                Some(format.span()),
                format!(
                    "`format = {other}` is not supported: this reader understands format \
                     {FORMAT_VERSION} only; convert the dataset or use a trackbelt that \
                     reads format {other}"
                ),
            )),
            other => Err(self.error(
                Some(format.span()),
                format!(
                    "`format` must be the integer {FORMAT_VERSION}, found {}",
                    describe_value(other)
                ),
            )),
        }
    }

    /// Where the key at `path` is written.
    fn key_span(&self, path: &KeyPath) -> Option<Range<usize>> {
        let keys = self
            .keys
            .get_or_init(|| toml_edit::ImDocument::parse(self.text).ok())
            .as_ref()?;
        let (last, parents) = path.0.split_last()?;
        let mut item = keys.as_item();
        for step in parents {
            item = match step {
                Step::Key(key) => item.get(key.as_str()),
                Step::Index(index) => item.get(*index),
            }?;
        }
        match last {
            Step::Key(key) => item.as_table_like()?.key(key)?.span(),
            Step::Index(_) => None,
        }
    }

    /// One warning `"FILE:LINE: unknown key …"` per unknown key, in file order.
    fn unknown_key_warnings(&self, unknown: &[KeyPath]) -> Vec<String> {
        let mut warnings: Vec<(Option<usize>, String)> = unknown
            .iter()
            .map(|path| {
                let line = self.key_span(path).map(|span| self.line(span.start));
                (
                    line,
                    format!("{}: {}", location(self.path, line), path.warning()),
                )
            })
            .collect();
        warnings.sort_by_key(|(line, _)| *line);
        warnings.into_iter().map(|(_, warning)| warning).collect()
    }
}

/// One step on the way to a key: a key of a table or an index of an array.
#[derive(Debug)]
enum Step {
    Key(String),
    Index(usize),
}

/// The way from the top of the manifest to a key, e.g. `static`, 0, `operator`.
#[derive(Debug)]
struct KeyPath(Vec<Step>);

impl KeyPath {
    /// The path `serde_ignored` reports for an unknown key, without the steps
    /// that [`Spanned`] adds inside the value it wraps.
    fn of(path: &serde_ignored::Path<'_>) -> Self {
        fn walk(path: &serde_ignored::Path<'_>, steps: &mut Vec<Step>) {
            use serde_ignored::Path;
            match path {
                Path::Root => {}
                Path::Seq { parent, index } => {
                    walk(parent, steps);
                    steps.push(Step::Index(*index));
                }
                Path::Map { parent, key } => {
                    walk(parent, steps);
                    // `Spanned<T>` reads its value as a field of this name.
                    if !key.starts_with("$__serde_spanned_private_") {
                        steps.push(Step::Key(key.clone()));
                    }
                }
                Path::Some { parent }
                | Path::NewtypeStruct { parent }
                | Path::NewtypeVariant { parent } => walk(parent, steps),
            }
        }
        let mut steps = Vec::new();
        walk(path, &mut steps);
        Self(steps)
    }

    /// `unknown key `KEY` in PLACE ignored (…)`.
    fn warning(&self) -> String {
        let place = match self.0.as_slice() {
            [Step::Key(array), Step::Index(index), _] => {
                format!(" in {}", entry_name(array, *index, None))
            }
            [Step::Key(table), _] => format!(" in [{table}]"),
            _ => String::new(),
        };
        let key = match self.0.last() {
            Some(Step::Key(key)) => key.as_str(),
            _ => "",
        };
        format!(
            "unknown key `{key}`{place} ignored (format {FORMAT_VERSION} does not define it; \
             check its spelling)"
        )
    }
}

/// Short description of a TOML value for messages.
fn describe_value(value: &Value) -> String {
    match value {
        Value::String(s) if s.chars().count() <= 40 => format!("the string {s:?}"),
        Value::Integer(i) => format!("the integer {i}"),
        Value::Float(x) => format!("the float {x}"),
        Value::Boolean(b) => format!("the boolean {b}"),
        Value::String(_) => "a long string".to_owned(),
        Value::Datetime(_) => "a date-time".to_owned(),
        Value::Array(_) => "an array".to_owned(),
        Value::Table(_) => "a table".to_owned(),
    }
}

/// Only `format`, read first.
#[derive(Deserialize)]
struct FormatProbe {
    format: Option<Spanned<Value>>,
}

/// A value as written in the manifest, with its place; `None` when absent.
///
/// Values are typed and checked after parsing (see [`Site`]), so that a
/// message can name the key and say how to fix the value.
type Field = Option<Spanned<Value>>;

/// A key and its value, as [`Site`] reads them.
type Keyed<'a> = (&'static str, &'a Field);

/// `key!(raw.hs_mm)` is `("hs_mm", &raw.hs_mm)`: a field of a raw table with
/// its key, which is the field's name.
macro_rules! key {
    ($raw:ident . $field:ident) => {
        (stringify!($field), &$raw.$field)
    };
}

/// The manifest as written (and as [`write()`] renders it). Unknown keys are
/// left to `serde_ignored`.
#[derive(Deserialize, Serialize)]
struct RawManifest {
    /// Checked before, by [`Doc::check_format`]; named here so that it is not
    /// reported as unknown.
    #[serde(rename = "format")]
    _format: Field,
    name: Field,
    source: Field,
    belt: Option<Table<RawBelt>>,
    #[serde(rename = "static", default, skip_serializing_if = "Entries::is_empty")]
    statics: Entries<RawStatic>,
    #[serde(rename = "dynamic", default, skip_serializing_if = "Entries::is_empty")]
    dynamics: Entries<RawDynamic>,
    #[serde(rename = "scroll", default, skip_serializing_if = "Entries::is_empty")]
    scrolls: Entries<RawScroll>,
}

/// `[belt]` as written.
#[derive(Deserialize, Serialize)]
struct RawBelt {
    length_mm: Field,
    width_mm: Field,
    thickness_mm: Field,
    mass_kg: Field,
    grousers: Field,
    grouser_pitch_mm: Field,
}

/// A `[[static]]` entry as written.
#[derive(Deserialize, Serialize)]
struct RawStatic {
    label: Field,
    hs_mm: Field,
    ws_mm: Field,
}

/// A `[[dynamic]]` entry as written.
#[derive(Deserialize, Serialize)]
struct RawDynamic {
    label: Field,
    roller_kg: Field,
    hd_mm: Field,
    wd_mm: Field,
    period_s: Field,
    log_decrement: Field,
    series: Field,
    settled_hs_mm: Field,
}

/// A `[[scroll]]` entry as written.
#[derive(Deserialize, Serialize)]
struct RawScroll {
    label: Field,
    drive_diameter_mm: Field,
    idler_diameter_mm: Field,
    center_distance_mm: Field,
    idler_force_n: Field,
    series: Field,
}

/// A table kind of the manifest, named in type errors.
trait Expecting {
    /// Shown in type errors: "expected {EXPECTING}".
    const EXPECTING: &'static str;
}

impl Expecting for RawBelt {
    const EXPECTING: &'static str = "the [belt] table";
}

impl Expecting for RawStatic {
    const EXPECTING: &'static str = "a [[static]] entry (a table)";
}

impl Expecting for RawDynamic {
    const EXPECTING: &'static str = "a [[dynamic]] entry (a table)";
}

impl Expecting for RawScroll {
    const EXPECTING: &'static str = "a [[scroll]] entry (a table)";
}

/// A TOML table read into the derived struct `T`. Only a table is accepted: a
/// derived struct alone would also take an array, as its fields in order.
#[derive(Serialize)]
#[serde(transparent)]
struct Table<T>(T);

impl<'de, T: Deserialize<'de> + Expecting> Deserialize<'de> for Table<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct TableVisitor<T>(PhantomData<T>);

        impl<'de, T: Deserialize<'de> + Expecting> Visitor<'de> for TableVisitor<T> {
            type Value = T;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(T::EXPECTING)
            }

            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
                T::deserialize(MapAccessDeserializer::new(map))
            }
        }

        deserializer
            .deserialize_map(TableVisitor(PhantomData))
            .map(Table)
    }
}

/// An array of tables; each entry's span starts at its header.
#[derive(Serialize)]
#[serde(transparent)]
struct Entries<T>(Vec<Spanned<Table<T>>>);

impl<T> Entries<T> {
    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<T> Default for Entries<T> {
    fn default() -> Self {
        Self(Vec::new())
    }
}

impl<'de, T: Deserialize<'de> + Expecting> Deserialize<'de> for Entries<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct EntriesVisitor<T>(PhantomData<T>);

        impl<'de, T: Deserialize<'de> + Expecting> Visitor<'de> for EntriesVisitor<T> {
            type Value = Entries<T>;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(
                    "an array of tables, written with one double-bracket header like \
                     [[static]] per entry",
                )
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut entries = Vec::new();
                while let Some(entry) = seq.next_element()? {
                    entries.push(entry);
                }
                Ok(Entries(entries))
            }
        }

        deserializer.deserialize_seq(EntriesVisitor(PhantomData))
    }
}

/// Reads typed values out of one table, naming it in errors.
struct Site<'a> {
    doc: &'a Doc<'a>,
    /// How messages name the table, e.g. `[belt]`; empty for the top level.
    what: String,
    /// Where the table starts, for errors about missing keys.
    span: Option<Range<usize>>,
}

impl Site<'_> {
    fn error(&self, span: Option<Range<usize>>, message: String) -> DatasetError {
        if self.what.is_empty() {
            self.doc.error(span, message)
        } else {
            self.doc.error(span, format!("{}: {message}", self.what))
        }
    }

    fn missing(&self, key: &str, kind: &str) -> DatasetError {
        self.error(
            self.span.clone(),
            format!("missing required `{key}` ({kind}); add it"),
        )
    }

    fn number(&self, (key, field): Keyed<'_>, rule: Rule) -> Result<Option<f64>, DatasetError> {
        let Some(field) = field else {
            return Ok(None);
        };
        let span = Some(field.span());
        let number = match field.get_ref() {
            Value::Integer(i) => *i as f64,
            Value::Float(x) => *x,
            value @ Value::String(_) => {
                return Err(self.error(
                    span,
                    format!(
                        "`{key}` must be a number, found {}; write the number without quotes",
                        describe_value(value)
                    ),
                ))
            }
            other => {
                return Err(self.error(
                    span,
                    format!("`{key}` must be a number, found {}", describe_value(other)),
                ))
            }
        };
        rule.check(key, number)
            .map_err(|reason| self.error(span, reason))?;
        Ok(Some(number))
    }

    fn required_number(&self, keyed: Keyed<'_>, rule: Rule) -> Result<f64, DatasetError> {
        self.number(keyed, rule)?
            .ok_or_else(|| self.missing(keyed.0, rule.describe()))
    }

    fn count(&self, (key, field): Keyed<'_>) -> Result<Option<u32>, DatasetError> {
        let Some(field) = field else {
            return Ok(None);
        };
        let value = field.get_ref();
        let count = match value {
            Value::Integer(i) => u32::try_from(*i).ok(),
            Value::Float(x) if x.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(x) => {
                Some(*x as u32)
            }
            _ => None,
        };
        count.map(Some).ok_or_else(|| {
            self.error(
                Some(field.span()),
                format!(
                    "`{key}` must be a whole number, 0 or more, found {}",
                    describe_value(value)
                ),
            )
        })
    }

    fn text(&self, (key, field): Keyed<'_>) -> Result<Option<String>, DatasetError> {
        let Some(field) = field else {
            return Ok(None);
        };
        match field.get_ref() {
            Value::String(s) => Ok(Some(s.clone())),
            other => Err(self.error(
                Some(field.span()),
                format!(
                    "`{key}` must be text in quotes, found {}",
                    describe_value(other)
                ),
            )),
        }
    }

    /// A required, non-blank text value.
    fn required_text(&self, keyed: Keyed<'_>) -> Result<String, DatasetError> {
        let text = self
            .text(keyed)?
            .ok_or_else(|| self.missing(keyed.0, "text in quotes"))?;
        if text.trim().is_empty() {
            return Err(self.error(
                keyed.1.as_ref().map(Spanned::span),
                format!("`{}` must not be empty", keyed.0),
            ));
        }
        Ok(text)
    }
}

/// Builds a [`Dataset`] from a parsed manifest, loading the series files.
struct Loader<'a> {
    doc: &'a Doc<'a>,
    dir: &'a Path,
    warnings: Vec<String>,
}

impl Loader<'_> {
    fn dataset(&mut self, raw: &RawManifest) -> Result<Dataset, DatasetError> {
        let top = Site {
            doc: self.doc,
            what: String::new(),
            span: None,
        };
        let name = top.required_text(key!(raw.name))?;
        let source = top.text(key!(raw.source))?;
        let belt = self.belt(raw.belt.as_ref())?;
        if raw.statics.is_empty() && raw.dynamics.is_empty() && raw.scrolls.is_empty() {
            return Err(DatasetError::EmptyDataset {
                path: self.doc.path.to_path_buf(),
                line: self.doc.line(self.doc.text.trim_end().len()),
            });
        }
        let statics = self.entries(
            "static",
            &raw.statics,
            |e| key!(e.label),
            Self::static_entry,
        )?;
        let dynamics = self.entries(
            "dynamic",
            &raw.dynamics,
            |e| key!(e.label),
            Self::dynamic_entry,
        )?;
        let scrolls = self.entries(
            "scroll",
            &raw.scrolls,
            |e| key!(e.label),
            Self::scroll_entry,
        )?;
        Ok(Dataset {
            dir: self.dir.to_path_buf(),
            name,
            source,
            belt,
            statics,
            dynamics,
            scrolls,
            warnings: std::mem::take(&mut self.warnings),
        })
    }

    fn belt(&self, belt: Option<&Table<RawBelt>>) -> Result<BeltSpec, DatasetError> {
        let Some(Table(raw)) = belt else {
            return Err(self.doc.error(
                None,
                "missing [belt] table; add it with length_mm, width_mm, thickness_mm and mass_kg",
            ));
        };
        let site = Site {
            doc: self.doc,
            what: "[belt]".to_owned(),
            // Missing keys are reported at the `belt` key: a table written
            // with dotted keys (`belt.length_mm = …`) has no span of its own.
            span: self
                .doc
                .key_span(&KeyPath(vec![Step::Key("belt".to_owned())])),
        };
        Ok(BeltSpec {
            length_mm: site.required_number(key!(raw.length_mm), Rule::Positive)?,
            width_mm: site.required_number(key!(raw.width_mm), Rule::Positive)?,
            thickness_mm: site.required_number(key!(raw.thickness_mm), Rule::Positive)?,
            mass_kg: site.required_number(key!(raw.mass_kg), Rule::Positive)?,
            grousers: site.count(key!(raw.grousers))?,
            grouser_pitch_mm: site.number(key!(raw.grouser_pitch_mm), Rule::Positive)?,
        })
    }

    /// Converts every entry of one array with `convert`; `label` gives an
    /// entry's label, which names the entry in messages.
    fn entries<R, T>(
        &mut self,
        array: &str,
        entries: &Entries<R>,
        label: fn(&R) -> Keyed<'_>,
        convert: fn(&mut Self, &Site<'_>, &R) -> Result<T, DatasetError>,
    ) -> Result<Vec<T>, DatasetError> {
        let mut out = Vec::with_capacity(entries.0.len());
        for (index, entry) in entries.0.iter().enumerate() {
            let Table(raw) = entry.get_ref();
            let mut site = Site {
                doc: self.doc,
                what: entry_name(array, index, None),
                span: Some(entry.span()),
            };
            let label = site.text(label(raw))?;
            site.what = entry_name(array, index, label.as_deref());
            out.push(convert(self, &site, raw)?);
        }
        Ok(out)
    }

    fn static_entry(
        &mut self,
        site: &Site<'_>,
        raw: &RawStatic,
    ) -> Result<StaticEntry, DatasetError> {
        Ok(StaticEntry {
            label: site.text(key!(raw.label))?,
            hs_mm: site.required_number(key!(raw.hs_mm), Rule::Positive)?,
            ws_mm: site.required_number(key!(raw.ws_mm), Rule::Positive)?,
        })
    }

    fn dynamic_entry(
        &mut self,
        site: &Site<'_>,
        raw: &RawDynamic,
    ) -> Result<DynamicEntry, DatasetError> {
        let mut entry = DynamicEntry {
            label: site.text(key!(raw.label))?,
            roller_kg: site.required_number(key!(raw.roller_kg), Rule::Positive)?,
            hd_mm: site.number(key!(raw.hd_mm), Rule::Positive)?,
            wd_mm: site.number(key!(raw.wd_mm), Rule::Positive)?,
            period_s: site.number(key!(raw.period_s), Rule::Positive)?,
            log_decrement: site.number(key!(raw.log_decrement), Rule::Finite)?,
            settled_hs_mm: site.number(key!(raw.settled_hs_mm), Rule::Positive)?,
            series: None,
        };
        if let Some(file) = site.text(key!(raw.series))? {
            let mut columns = self.series(site, &file, &raw.series, &DYNAMIC_COLUMNS)?;
            entry.series = Some(DynamicSeries {
                file: PathBuf::from(file),
                t_s: columns.remove(TIME_COLUMN).unwrap_or_default(),
                a_height_mm: columns.remove("a_height_mm").unwrap_or_default(),
                a_x_mm: columns.remove("a_x_mm"),
            });
        }
        Ok(entry)
    }

    fn scroll_entry(
        &mut self,
        site: &Site<'_>,
        raw: &RawScroll,
    ) -> Result<ScrollEntry, DatasetError> {
        let label = site.text(key!(raw.label))?;
        let drive_diameter_mm =
            site.required_number(key!(raw.drive_diameter_mm), Rule::Positive)?;
        let idler_diameter_mm =
            site.required_number(key!(raw.idler_diameter_mm), Rule::Positive)?;
        let center_distance_mm =
            site.required_number(key!(raw.center_distance_mm), Rule::Positive)?;
        let idler_force_n = site.number(key!(raw.idler_force_n), Rule::NonNegative)?;
        let file = site
            .text(key!(raw.series))?
            .ok_or_else(|| site.missing("series", "the path of the scroll CSV file"))?;
        let mut columns = self.series(site, &file, &raw.series, &SCROLL_COLUMNS)?;
        Ok(ScrollEntry {
            label,
            drive_diameter_mm,
            idler_diameter_mm,
            center_distance_mm,
            idler_force_n,
            series: ScrollSeries {
                file: PathBuf::from(file),
                t_s: columns.remove(TIME_COLUMN).unwrap_or_default(),
                omega_rad_s: columns.remove("omega_rad_s").unwrap_or_default(),
                torque_nm: columns.remove("torque_nm").unwrap_or_default(),
                belt_temp_c: columns.remove("belt_temp_c"),
            },
        })
    }

    /// Reads the series file `file`, named by the `series` value `field` of `site`.
    fn series(
        &mut self,
        site: &Site<'_>,
        file: &str,
        field: &Field,
        columns: &Columns,
    ) -> Result<BTreeMap<&'static str, Vec<f64>>, DatasetError> {
        let span = field.as_ref().map(Spanned::span);
        if file.trim().is_empty() {
            return Err(site.error(span, "`series` must name a CSV file".to_owned()));
        }
        // Inside the dataset: no absolute path, no `..` (found by the
        // generated tests: `series = "/"` read the file system's root).
        if Path::new(file)
            .components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(site.error(
                span,
                format!(
                    "`series = {file:?}`: series paths are relative to the dataset directory \
                     and stay inside it (no absolute path, no `..`)"
                ),
            ));
        }
        let path = self.dir.join(file);
        let bytes = match fs::read(&path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Err(DatasetError::MissingSeries {
                    path,
                    manifest: self.doc.path.to_path_buf(),
                    line: span.map_or(1, |span| self.doc.line(span.start)),
                })
            }
            Err(e) => return Err(io_error(&path, "read the series file")(e)),
        };
        parse_series(&path, &bytes, columns, &mut self.warnings)
    }
}

// ---------------------------------------------------------------------------
// Loading: CSV series
// ---------------------------------------------------------------------------

fn series_error(path: &Path, line: Option<usize>, message: impl Into<String>) -> DatasetError {
    DatasetError::Series {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Which header fields hold the columns in use.
struct ColumnLayout {
    /// Number of fields in the header; every row must have as many.
    width: usize,
    /// Columns in use, with their field index.
    used: Vec<(&'static str, usize)>,
}

impl ColumnLayout {
    fn from_header(
        path: &Path,
        header: &csv::ByteRecord,
        line: usize,
        columns: &Columns,
    ) -> Result<Self, DatasetError> {
        let names: Vec<String> = header
            .iter()
            .map(|cell| {
                String::from_utf8_lossy(cell)
                    .trim_start_matches('\u{feff}')
                    .trim()
                    .to_owned()
            })
            .collect();
        let mut used = Vec::new();
        let wanted = columns.required.iter().map(|c| (*c, true));
        let wanted = wanted.chain(columns.optional.iter().map(|c| (*c, false)));
        for (column, required) in wanted {
            let mut found = names.iter().enumerate().filter(|(_, n)| *n == column);
            match (found.next(), found.next()) {
                (Some((index, _)), None) => used.push((column, index)),
                (Some(_), Some(_)) => {
                    return Err(series_error(
                        path,
                        Some(line),
                        format!("column `{column}` appears more than once in the header; keep one"),
                    ))
                }
                (None, _) if required => {
                    return Err(series_error(
                        path,
                        Some(line),
                        format!(
                            "missing required column `{column}` (the header has: {}); the \
                             header row must name the columns {}",
                            names.join(", "),
                            columns.required.join(", ")
                        ),
                    ))
                }
                (None, _) => {}
            }
        }
        Ok(Self {
            width: names.len(),
            used,
        })
    }

    /// The values of the used columns, or why the row is bad.
    fn parse_row(&self, record: &csv::ByteRecord) -> Result<Vec<f64>, String> {
        if record.len() != self.width {
            return Err(format!(
                "{} fields where the header has {}",
                record.len(),
                self.width
            ));
        }
        self.used
            .iter()
            .map(|&(column, index)| parse_cell(record.get(index).unwrap_or_default(), column))
            .collect()
    }
}

fn parse_cell(cell: &[u8], column: &str) -> Result<f64, String> {
    let text = std::str::from_utf8(cell)
        .map_err(|_| format!("`{column}` is not valid UTF-8 text"))?
        .trim();
    if text.is_empty() {
        return Err(format!("empty `{column}`"));
    }
    let value: f64 = text
        .parse()
        .map_err(|_| format!("`{column}` = {text:?} is not a number"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("`{column}` = {text} is not finite"))
    }
}

/// 1-based line of `bytes` on which `record` starts, or `fallback`.
///
/// The reader's own line count is not used: it points at the blank lines it
/// skipped before the record, not at the record.
fn record_line(bytes: &[u8], record: &csv::ByteRecord, fallback: usize) -> usize {
    let Some(offset) = record
        .position()
        .and_then(|p| usize::try_from(p.byte()).ok())
    else {
        return fallback;
    };
    let Some(rest) = bytes.get(offset..) else {
        return fallback;
    };
    let blank = rest
        .iter()
        .take_while(|&&b| b == b'\n' || b == b'\r')
        .count();
    1 + bytes[..offset + blank]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// Whether `record` comes from a line holding only whitespace.
fn is_blank(record: &csv::ByteRecord) -> bool {
    record.iter().all(<[u8]>::is_empty) && record.len() <= 1
}

fn csv_error(path: &Path, error: &csv::Error) -> DatasetError {
    series_error(path, None, format!("unreadable CSV: {error}"))
}

/// Parses the contents of series file `path`: returns the values of every
/// column of `columns` the header names, skipping (and reporting in
/// `warnings`) bad rows.
fn parse_series(
    path: &Path,
    bytes: &[u8],
    columns: &Columns,
    warnings: &mut Vec<String>,
) -> Result<BTreeMap<&'static str, Vec<f64>>, DatasetError> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(bytes);
    let mut records = reader
        .byte_records()
        .filter(|record| !matches!(record, Ok(r) if is_blank(r)));
    let header = records
        .next()
        .ok_or_else(|| {
            series_error(
                path,
                None,
                format!(
                    "the file is empty; it needs a header row ({}) and data rows",
                    columns.required.join(",")
                ),
            )
        })?
        .map_err(|e| csv_error(path, &e))?;
    let layout = ColumnLayout::from_header(path, &header, record_line(bytes, &header, 1), columns)?;

    let mut rows = ParsedRows::new(layout.used.len());
    for record in records {
        let record = record.map_err(|e| csv_error(path, &e))?;
        let line = record_line(bytes, &record, rows.count + 2);
        rows.push(line, layout.parse_row(&record));
    }
    rows.check(path)?;
    warnings.extend(
        rows.bad.iter().map(|(line, reason)| {
            format!("{}: {reason}; row skipped", location(path, Some(*line)))
        }),
    );
    Ok(layout
        .used
        .iter()
        .map(|&(name, _)| name)
        .zip(rows.values)
        .collect())
}

/// The data rows of a series file, sorted into good values and bad rows.
struct ParsedRows {
    /// Number of data rows, good and bad.
    count: usize,
    /// Values of the good rows, one vector per used column.
    values: Vec<Vec<f64>>,
    /// Line of each good row.
    lines: Vec<usize>,
    /// Line of each bad row, with the reason.
    bad: Vec<(usize, String)>,
}

impl ParsedRows {
    fn new(columns: usize) -> Self {
        Self {
            count: 0,
            values: vec![Vec::new(); columns],
            lines: Vec::new(),
            bad: Vec::new(),
        }
    }

    fn push(&mut self, line: usize, row: Result<Vec<f64>, String>) {
        self.count += 1;
        match row {
            Ok(row) => {
                self.lines.push(line);
                for (column, value) in self.values.iter_mut().zip(row) {
                    column.push(value);
                }
            }
            Err(reason) => self.bad.push((line, reason)),
        }
    }

    /// Errors for a file without data rows, with too many bad rows, or with
    /// time not strictly increasing over the good rows.
    fn check(&self, path: &Path) -> Result<(), DatasetError> {
        if self.count == 0 {
            return Err(series_error(
                path,
                None,
                "no data rows after the header; add the measurements or remove the `series` \
                 entry",
            ));
        }
        if self.bad.len().saturating_mul(100) > self.count.saturating_mul(MAX_BAD_ROWS_PERCENT) {
            let first = self
                .bad
                .first()
                .map(|(line, reason)| format!("line {line}: {reason}"))
                .unwrap_or_default();
            return Err(DatasetError::TooManyBadRows {
                path: path.to_path_buf(),
                bad: self.bad.len(),
                rows: self.count,
                first,
            });
        }
        // The time column is the first one in use.
        let times = self.values.first().map(Vec::as_slice).unwrap_or_default();
        check_time_order(self.lines.iter().copied().zip(times.iter().copied()))
            .map_err(|(line, reason)| series_error(path, Some(line), reason))
    }
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

/// Writes `dataset` as a new dataset in directory `dir`: `dataset.toml` and
/// the CSV series files it names (at their [`DynamicSeries::file`] /
/// [`ScrollSeries::file`] paths, relative to `dir`).
///
/// Creates `dir` if missing. Refuses, with [`DatasetError::AlreadyExists`],
/// when `dir/dataset.toml` or any target CSV file already exists: it never
/// overwrites user data. Checks the dataset as [`load()`] would before writing
/// anything. Each file is written under a temporary name and then renamed;
/// the manifest comes last, so an interrupted write never leaves a manifest
/// naming missing files. [`Dataset::dir`] and [`Dataset::warnings`] are not
/// written.
pub fn write(dataset: &Dataset, dir: &Path) -> Result<(), DatasetError> {
    let files = render(dataset, dir)?;
    for file in &files {
        refuse_existing(&file.path)?;
    }
    let mut written: Vec<&Path> = Vec::new();
    for file in &files {
        if let Err(e) = write_new_file(&file.path, file.contents.as_bytes()) {
            for path in written {
                // Best effort: these files did not exist before this call.
                let _ = fs::remove_file(path);
            }
            return Err(e);
        }
        written.push(&file.path);
    }
    Ok(())
}

/// A file to be written.
struct PendingFile {
    path: PathBuf,
    contents: String,
}

/// Validates `dataset` and renders all its files, the manifest last.
fn render(dataset: &Dataset, dir: &Path) -> Result<Vec<PendingFile>, DatasetError> {
    let mut plan = WritePlan::new(dir);
    check_manifest(dataset).map_err(|message| plan.manifest_error(message))?;
    let dynamic_files = dataset
        .dynamics
        .iter()
        .enumerate()
        .map(|(index, entry)| {
            let what = entry_name("dynamic", index, entry.label.as_deref());
            entry
                .series
                .as_ref()
                .map(|s| plan.add_series(&what, &s.file, &dynamic_columns(s)))
                .transpose()
        })
        .collect::<Result<Vec<_>, _>>()?;
    let scroll_files = dataset
        .scrolls
        .iter()
        .enumerate()
        .map(|(index, entry)| {
            let what = entry_name("scroll", index, entry.label.as_deref());
            let s = &entry.series;
            plan.add_series(&what, &s.file, &scroll_columns(s))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let manifest = render_manifest(dataset, &dynamic_files, &scroll_files)
        .map_err(|e| plan.manifest_error(format!("cannot render the manifest: {e}")))?;
    Ok(plan.finish(manifest))
}

/// The columns of a dynamic series, `None` for an absent optional one.
fn dynamic_columns(s: &DynamicSeries) -> [(&'static str, Option<&[f64]>); 3] {
    [
        (TIME_COLUMN, Some(&s.t_s)),
        ("a_height_mm", Some(&s.a_height_mm)),
        ("a_x_mm", s.a_x_mm.as_deref()),
    ]
}

/// The columns of a scroll series, `None` for an absent optional one.
fn scroll_columns(s: &ScrollSeries) -> [(&'static str, Option<&[f64]>); 4] {
    [
        (TIME_COLUMN, Some(&s.t_s)),
        ("omega_rad_s", Some(&s.omega_rad_s)),
        ("torque_nm", Some(&s.torque_nm)),
        ("belt_temp_c", s.belt_temp_c.as_deref()),
    ]
}

/// The files of a dataset being written, each checked and rendered.
struct WritePlan<'a> {
    dir: &'a Path,
    manifest: PathBuf,
    files: Vec<PendingFile>,
    /// Paths relative to `dir` already taken, to catch two entries sharing
    /// one file.
    taken: BTreeSet<PathBuf>,
}

impl<'a> WritePlan<'a> {
    fn new(dir: &'a Path) -> Self {
        Self {
            dir,
            manifest: dir.join(MANIFEST_FILE),
            files: Vec::new(),
            taken: BTreeSet::from([PathBuf::from(MANIFEST_FILE)]),
        }
    }

    fn manifest_error(&self, message: String) -> DatasetError {
        DatasetError::Manifest {
            path: self.manifest.clone(),
            line: None,
            message,
        }
    }

    /// Checks and renders the series file `file` of entry `what`; returns its
    /// path as written in the manifest.
    fn add_series(
        &mut self,
        what: &str,
        file: &Path,
        columns: &[(&str, Option<&[f64]>)],
    ) -> Result<String, DatasetError> {
        let (relative, name) = relative_series_path(file).map_err(|reason| {
            self.manifest_error(format!("{what}: series file {}: {reason}", file.display()))
        })?;
        let path = self.dir.join(&relative);
        if !self.taken.insert(relative) {
            return Err(self.manifest_error(format!(
                "{what}: series file `{name}` is also used by another entry or is the \
                 manifest; give every series its own file"
            )));
        }
        let contents = render_csv(columns).map_err(|message| series_error(&path, None, message))?;
        self.files.push(PendingFile { path, contents });
        Ok(name)
    }

    /// All files, the manifest (with `contents`) last.
    fn finish(mut self, contents: String) -> Vec<PendingFile> {
        self.files.push(PendingFile {
            path: self.manifest,
            contents,
        });
        self.files
    }
}

/// Checks the values that go into `dataset.toml` against the rules of [`load()`].
fn check_manifest(dataset: &Dataset) -> Result<(), String> {
    if dataset.name.trim().is_empty() {
        return Err("`name` must not be empty".to_owned());
    }
    if dataset.statics.is_empty() && dataset.dynamics.is_empty() && dataset.scrolls.is_empty() {
        return Err(
            "empty dataset: there is no static, dynamic or scroll entry; add at least one"
                .to_owned(),
        );
    }
    let b = &dataset.belt;
    check_fields(
        "[belt]",
        &[
            ("length_mm", Some(b.length_mm), Rule::Positive),
            ("width_mm", Some(b.width_mm), Rule::Positive),
            ("thickness_mm", Some(b.thickness_mm), Rule::Positive),
            ("mass_kg", Some(b.mass_kg), Rule::Positive),
            ("grouser_pitch_mm", b.grouser_pitch_mm, Rule::Positive),
        ],
    )?;
    for (index, s) in dataset.statics.iter().enumerate() {
        check_fields(
            &entry_name("static", index, s.label.as_deref()),
            &[
                ("hs_mm", Some(s.hs_mm), Rule::Positive),
                ("ws_mm", Some(s.ws_mm), Rule::Positive),
            ],
        )?;
    }
    for (index, d) in dataset.dynamics.iter().enumerate() {
        check_fields(
            &entry_name("dynamic", index, d.label.as_deref()),
            &[
                ("roller_kg", Some(d.roller_kg), Rule::Positive),
                ("hd_mm", d.hd_mm, Rule::Positive),
                ("wd_mm", d.wd_mm, Rule::Positive),
                ("period_s", d.period_s, Rule::Positive),
                ("log_decrement", d.log_decrement, Rule::Finite),
                ("settled_hs_mm", d.settled_hs_mm, Rule::Positive),
            ],
        )?;
    }
    for (index, s) in dataset.scrolls.iter().enumerate() {
        check_fields(
            &entry_name("scroll", index, s.label.as_deref()),
            &[
                (
                    "drive_diameter_mm",
                    Some(s.drive_diameter_mm),
                    Rule::Positive,
                ),
                (
                    "idler_diameter_mm",
                    Some(s.idler_diameter_mm),
                    Rule::Positive,
                ),
                (
                    "center_distance_mm",
                    Some(s.center_distance_mm),
                    Rule::Positive,
                ),
                ("idler_force_n", s.idler_force_n, Rule::NonNegative),
            ],
        )?;
    }
    Ok(())
}

fn check_fields(what: &str, fields: &[(&str, Option<f64>, Rule)]) -> Result<(), String> {
    for &(key, value, rule) in fields {
        if let Some(value) = value {
            rule.check(key, value)
                .map_err(|reason| format!("{what}: {reason}"))?;
        }
    }
    Ok(())
}

/// Normalises a series path for writing: it must stay inside the dataset
/// directory. Returns the relative path and its `/`-separated text.
fn relative_series_path(file: &Path) -> Result<(PathBuf, String), String> {
    let mut parts = Vec::new();
    for component in file.components() {
        match component {
            Component::Normal(part) => parts.push(
                part.to_str()
                    .ok_or("the path is not valid UTF-8; rename the file")?,
            ),
            Component::CurDir => {}
            _ => {
                return Err(
                    "the path must be relative and stay inside the dataset directory \
                     (no root, no `..`)"
                        .to_owned(),
                )
            }
        }
    }
    if parts.is_empty() {
        return Err("the path is empty; name a CSV file".to_owned());
    }
    Ok((parts.iter().collect(), parts.join("/")))
}

/// Renders series columns as CSV; `None` columns are left out. Checks what
/// [`load()`] would check: equal lengths, at least one row, finite values,
/// strictly increasing time (the first column).
fn render_csv(columns: &[(&str, Option<&[f64]>)]) -> Result<String, String> {
    let present: Vec<(&str, &[f64])> = columns
        .iter()
        .filter_map(|&(name, values)| values.map(|v| (name, v)))
        .collect();
    let rows = present.first().map_or(0, |(_, v)| v.len());
    if rows == 0 {
        return Err("the series has no rows; a series needs at least one sample".to_owned());
    }
    for (name, values) in &present {
        if values.len() != rows {
            return Err(format!(
                "column `{name}` has {} values but `{TIME_COLUMN}` has {rows}; every column \
                 needs one value per time",
                values.len()
            ));
        }
        if let Some((row, value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!(
                "column `{name}` row {} is {value}; values must be finite",
                row + 1
            ));
        }
    }
    if let Some((_, times)) = present.first() {
        // Data row `i` is on line `i + 2` of the file (the header is line 1).
        check_time_order(times.iter().copied().enumerate().map(|(i, t)| (i + 2, t)))
            .map_err(|(line, reason)| format!("line {line}: {reason}"))?;
    }

    let mut csv = present
        .iter()
        .map(|(name, _)| *name)
        .collect::<Vec<_>>()
        .join(",");
    csv.push('\n');
    for row in 0..rows {
        let cells: Vec<String> = present
            .iter()
            .map(|(_, values)| values.get(row).map(f64::to_string).unwrap_or_default())
            .collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    Ok(csv)
}

/// A value to write: a [`Field`] without a place in a file.
fn written<V: Into<Value>>(value: Option<V>) -> Field {
    value.map(|value| Spanned::new(0..0, value.into()))
}

/// Entries to write.
fn written_entries<T>(entries: impl Iterator<Item = T>) -> Entries<T> {
    Entries(entries.map(|e| Spanned::new(0..0, Table(e))).collect())
}

/// Renders `dataset.toml` through the reader's raw structs; `dynamic_files`
/// and `scroll_files` hold the normalised series path of each entry.
fn render_manifest(
    dataset: &Dataset,
    dynamic_files: &[Option<String>],
    scroll_files: &[String],
) -> Result<String, toml::ser::Error> {
    let b = &dataset.belt;
    let raw = RawManifest {
        _format: written(Some(FORMAT_VERSION)),
        name: written(Some(dataset.name.as_str())),
        source: written(dataset.source.as_deref()),
        belt: Some(Table(RawBelt {
            length_mm: written(Some(b.length_mm)),
            width_mm: written(Some(b.width_mm)),
            thickness_mm: written(Some(b.thickness_mm)),
            mass_kg: written(Some(b.mass_kg)),
            grousers: written(b.grousers),
            grouser_pitch_mm: written(b.grouser_pitch_mm),
        })),
        statics: written_entries(dataset.statics.iter().map(|s| RawStatic {
            label: written(s.label.as_deref()),
            hs_mm: written(Some(s.hs_mm)),
            ws_mm: written(Some(s.ws_mm)),
        })),
        dynamics: written_entries(dataset.dynamics.iter().zip(dynamic_files).map(|(d, file)| {
            RawDynamic {
                label: written(d.label.as_deref()),
                roller_kg: written(Some(d.roller_kg)),
                hd_mm: written(d.hd_mm),
                wd_mm: written(d.wd_mm),
                period_s: written(d.period_s),
                log_decrement: written(d.log_decrement),
                series: written(file.as_deref()),
                settled_hs_mm: written(d.settled_hs_mm),
            }
        })),
        scrolls: written_entries(dataset.scrolls.iter().zip(scroll_files).map(|(s, file)| {
            RawScroll {
                label: written(s.label.as_deref()),
                drive_diameter_mm: written(Some(s.drive_diameter_mm)),
                idler_diameter_mm: written(Some(s.idler_diameter_mm)),
                center_distance_mm: written(Some(s.center_distance_mm)),
                idler_force_n: written(s.idler_force_n),
                series: written(Some(file.as_str())),
            }
        })),
    };
    let body = toml::to_string(&raw)?;
    Ok(format!(
        "# Measured-data format, version {FORMAT_VERSION} (see DATA.md). Written by trackbelt.\n{body}"
    ))
}

/// `Err(AlreadyExists)` if anything exists at `path`.
fn refuse_existing(path: &Path) -> Result<(), DatasetError> {
    match fs::symlink_metadata(path) {
        Ok(_) => Err(DatasetError::AlreadyExists {
            path: path.to_path_buf(),
        }),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(io_error(path, "check whether the file exists")(e)),
    }
}

/// Writes `contents` to a temporary file next to `path`, then moves it to
/// `path` unless something is there by then, creating parent directories as
/// needed. The temporary file is removed if anything fails.
fn write_new_file(path: &Path, contents: &[u8]) -> Result<(), DatasetError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    fs::create_dir_all(dir).map_err(io_error(dir, "create the directory"))?;
    refuse_existing(path)?;
    crate::atomic::persist_bytes(dir, path, contents, crate::atomic::Existing::Keep).map_err(
        |(action, e)| {
            if action == crate::atomic::MOVE && e.kind() == io::ErrorKind::AlreadyExists {
                DatasetError::AlreadyExists {
                    path: path.to_path_buf(),
                }
            } else if action == crate::atomic::MOVE {
                io_error(path, action)(e)
            } else {
                io_error(dir, action)(e)
            }
        },
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::{SystemTime, UNIX_EPOCH};

    /// The example dataset shipped with the project (Table 1 of the paper).
    const SHREDDER_TABLE1: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/shredder-table1");

    /// A directory under the system temp dir, removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(tag: &str) -> Self {
            static COUNTER: AtomicUsize = AtomicUsize::new(0);
            let nanos = SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos());
            let path = std::env::temp_dir().join(format!(
                "trackbelt-dataset-{tag}-{}-{nanos}-{}",
                std::process::id(),
                COUNTER.fetch_add(1, Ordering::SeqCst)
            ));
            fs::create_dir_all(&path).expect("create temp dir");
            Self(path)
        }

        fn path(&self) -> &Path {
            &self.0
        }

        fn put(&self, name: &str, contents: &str) {
            fs::write(self.0.join(name), contents).expect("write test file");
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    /// A valid manifest; the line numbers matter to the tests.
    const BASE: &str = r#"format = 1
name = "test"

[belt]
length_mm = 2450
width_mm = 160.0
thickness_mm = 8
mass_kg = 6.4

[[static]]
label = "a"
hs_mm = 329
ws_mm = 1068

[[dynamic]]
roller_kg = 1.3
series = "dyn.csv"
"#;

    /// 30 good data rows of a dynamic series, with `edit(i, row)` applied.
    fn dyn_csv(edit: impl Fn(usize, String) -> String) -> String {
        let mut csv = String::from("t_s,a_height_mm\n");
        for i in 0..30 {
            let row = format!("{},{}", i as f64 * 0.04, 300.0 - i as f64);
            csv.push_str(&edit(i, row));
            csv.push('\n');
        }
        csv
    }

    /// Loads a dataset made of `manifest` and the given files.
    fn load_with(manifest: &str, files: &[(&str, &str)]) -> Result<Dataset, DatasetError> {
        let dir = TempDir::new("load");
        dir.put(MANIFEST_FILE, manifest);
        for (name, contents) in files {
            dir.put(name, contents);
        }
        load(dir.path())
    }

    fn load_base(manifest: &str) -> Result<Dataset, DatasetError> {
        load_with(manifest, &[("dyn.csv", &dyn_csv(|_, row| row))])
    }

    fn error_of(result: Result<Dataset, DatasetError>) -> (DatasetError, String) {
        let error = result.expect_err("the load should fail");
        let message = error.to_string();
        (error, message)
    }

    #[test]
    fn loads_the_shredder_table1_dataset() {
        let dataset = load(Path::new(SHREDDER_TABLE1)).expect("load shredder-table1");
        assert_eq!(dataset.name, "shredder-table1");
        assert_eq!(dataset.statics.len(), 8);
        assert_eq!(dataset.dynamics.len(), 8);
        assert!(dataset.scrolls.is_empty());
        assert!(dataset.warnings.is_empty(), "{:?}", dataset.warnings);
        assert_eq!(dataset.belt.length_mm, 2450.0);
        assert_eq!(dataset.belt.mass_kg, 6.4);
        assert_eq!(dataset.belt.grousers, Some(38));
        assert_eq!(dataset.belt.grouser_pitch_mm, Some(64.5));
        assert_eq!(dataset.statics[0].label.as_deref(), Some("track1-run1"));

        let (hs, ws) = dataset.static_mean().expect("static mean");
        assert!((hs - 323.625).abs() < 1e-9, "hs mean {hs}");
        assert!((ws - 1062.25).abs() < 1e-9, "ws mean {ws}");

        let means = dataset.dynamic_means();
        let period = means.period_s.expect("period mean");
        assert_eq!(period.count, 8);
        assert!((period.value - 0.7375).abs() < 1e-12);
        assert_eq!(means.hd_mm.map(|m| m.count), Some(8));
        assert_eq!(means.settled_hs_mm, None);
    }

    fn sample_dataset() -> Dataset {
        let t: Vec<f64> = (0..50).map(|i| f64::from(i) * 0.04).collect();
        Dataset {
            dir: PathBuf::new(),
            name: "round-trip".to_owned(),
            source: Some("unit test, \"quoted\" source".to_owned()),
            belt: BeltSpec {
                length_mm: 2450.0,
                width_mm: 160.0,
                thickness_mm: 8.0,
                mass_kg: 6.4,
                grousers: Some(38),
                grouser_pitch_mm: Some(64.5),
            },
            statics: vec![
                StaticEntry {
                    label: Some("s1".to_owned()),
                    hs_mm: 329.0,
                    ws_mm: 1068.25,
                },
                StaticEntry {
                    label: None,
                    hs_mm: 0.1 + 0.2,
                    ws_mm: 1.0 / 3.0,
                },
            ],
            dynamics: vec![
                DynamicEntry {
                    label: Some("d1".to_owned()),
                    roller_kg: 1.3,
                    hd_mm: Some(231.0),
                    wd_mm: None,
                    period_s: Some(0.75),
                    log_decrement: Some(0.76),
                    settled_hs_mm: Some(329.0),
                    series: Some(DynamicSeries {
                        file: PathBuf::from("series/dynamic-1.csv"),
                        t_s: t.clone(),
                        a_height_mm: t.iter().map(|t| 231.0 + 20.0 * (7.0 * t).sin()).collect(),
                        a_x_mm: Some(t.iter().map(|t| 1e-3 * t).collect()),
                    }),
                },
                DynamicEntry {
                    label: None,
                    roller_kg: 2.0,
                    hd_mm: None,
                    wd_mm: Some(1080.0),
                    period_s: None,
                    log_decrement: None,
                    settled_hs_mm: None,
                    series: None,
                },
            ],
            scrolls: vec![ScrollEntry {
                label: Some("run-1".to_owned()),
                drive_diameter_mm: 300.0,
                idler_diameter_mm: 250.5,
                center_distance_mm: 738.0,
                idler_force_n: Some(500.0),
                series: ScrollSeries {
                    file: PathBuf::from("scroll-1.csv"),
                    t_s: t.clone(),
                    omega_rad_s: t.iter().map(|t| 2.0 + t).collect(),
                    torque_nm: t.iter().map(|t| 0.5 + 0.01 * t).collect(),
                    belt_temp_c: Some(t.iter().map(|t| 21.5 + t / 3.0).collect()),
                },
            }],
            warnings: Vec::new(),
        }
    }

    #[test]
    fn round_trip_write_then_load() {
        let tmp = TempDir::new("roundtrip");
        let dir = tmp.path().join("new-dataset");
        let mut expected = sample_dataset();
        write(&expected, &dir).expect("write");
        assert!(dir.join("series/dynamic-1.csv").is_file());

        let loaded = load(&dir).expect("load what was written");
        expected.dir = dir.clone();
        assert_eq!(loaded, expected);
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);

        // Columns in another order plus an unknown column: same data.
        let s = &expected.scrolls[0].series;
        let mut csv = String::from("belt_temp_c,motor_current_a,torque_nm,t_s,omega_rad_s\n");
        for i in 0..s.t_s.len() {
            let temp = s.belt_temp_c.as_ref().expect("temperatures")[i];
            csv.push_str(&format!(
                "{temp},{},{},{},{}\n",
                i % 7,
                s.torque_nm[i],
                s.t_s[i],
                s.omega_rad_s[i]
            ));
        }
        fs::write(dir.join("scroll-1.csv"), csv).expect("rewrite scroll csv");
        let reloaded = load(&dir).expect("load with an unknown column");
        assert_eq!(reloaded, expected);
    }

    #[test]
    fn write_leaves_only_the_dataset_files() {
        let tmp = TempDir::new("write-files");
        write(&sample_dataset(), tmp.path()).expect("write");
        let mut names: Vec<String> = fs::read_dir(tmp.path())
            .expect("read dir")
            .chain(fs::read_dir(tmp.path().join("series")).expect("read series dir"))
            .map(|entry| {
                entry
                    .expect("entry")
                    .file_name()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["dataset.toml", "dynamic-1.csv", "scroll-1.csv", "series"]
        );
        let manifest = fs::read_to_string(tmp.path().join(MANIFEST_FILE)).expect("read");
        let expected = r#"# Measured-data format, version 1 (see DATA.md). Written by trackbelt.
format = 1
name = "round-trip"
source = 'unit test, "quoted" source'

[belt]
length_mm = 2450.0
width_mm = 160.0
thickness_mm = 8.0
mass_kg = 6.4
grousers = 38
grouser_pitch_mm = 64.5

[[static]]
label = "s1"
hs_mm = 329.0
ws_mm = 1068.25

[[static]]
hs_mm = 0.30000000000000004
ws_mm = 0.3333333333333333

[[dynamic]]
label = "d1"
roller_kg = 1.3
hd_mm = 231.0
period_s = 0.75
log_decrement = 0.76
series = "series/dynamic-1.csv"
settled_hs_mm = 329.0

[[dynamic]]
roller_kg = 2.0
wd_mm = 1080.0

[[scroll]]
label = "run-1"
drive_diameter_mm = 300.0
idler_diameter_mm = 250.5
center_distance_mm = 738.0
idler_force_n = 500.0
series = "scroll-1.csv"
"#;
        assert_eq!(manifest, expected);
    }

    #[test]
    fn write_refuses_to_overwrite() {
        let tmp = TempDir::new("overwrite");
        let dataset = sample_dataset();
        write(&dataset, tmp.path()).expect("first write");
        let manifest_before = fs::read_to_string(tmp.path().join(MANIFEST_FILE)).expect("read");
        let error = write(&dataset, tmp.path()).expect_err("second write must fail");
        assert!(
            matches!(error, DatasetError::AlreadyExists { .. }),
            "{error}"
        );
        assert!(error.to_string().contains("already exists"));
        let manifest_after = fs::read_to_string(tmp.path().join(MANIFEST_FILE)).expect("read");
        assert_eq!(manifest_before, manifest_after);

        // A lone CSV in the way: nothing at all is written.
        let other = TempDir::new("overwrite-csv");
        other.put("scroll-1.csv", "user data\n");
        let error = write(&dataset, other.path()).expect_err("must not overwrite the CSV");
        assert!(error.to_string().contains("scroll-1.csv"), "{error}");
        assert!(!other.path().join(MANIFEST_FILE).exists());
        assert!(!other.path().join("series").exists());
        let kept = fs::read_to_string(other.path().join("scroll-1.csv")).expect("read");
        assert_eq!(kept, "user data\n");
    }

    #[test]
    fn write_rejects_paths_outside_the_dataset_and_invalid_values() {
        let tmp = TempDir::new("write-invalid");
        let mut dataset = sample_dataset();
        dataset.scrolls[0].series.file = PathBuf::from("../escape.csv");
        let message = write(&dataset, tmp.path()).expect_err("escape").to_string();
        assert!(
            message.contains("inside the dataset directory"),
            "{message}"
        );

        let mut dataset = sample_dataset();
        dataset.statics[1].hs_mm = -1.0;
        let message = write(&dataset, tmp.path())
            .expect_err("negative")
            .to_string();
        assert!(
            message.contains("hs_mm") && message.contains("[[static]] entry 2"),
            "{message}"
        );

        let mut dataset = sample_dataset();
        dataset.scrolls[0].series.torque_nm.pop();
        let message = write(&dataset, tmp.path()).expect_err("ragged").to_string();
        assert!(message.contains("torque_nm"), "{message}");
        assert!(fs::read_dir(tmp.path()).expect("read dir").next().is_none());
    }

    #[test]
    fn base_manifest_loads() {
        let dataset = load_base(BASE).expect("load");
        assert_eq!(dataset.statics[0].hs_mm, 329.0);
        assert_eq!(dataset.belt.width_mm, 160.0);
        let series = dataset.dynamics[0].series.as_ref().expect("series");
        assert_eq!(series.t_s.len(), 30);
        assert_eq!(series.a_x_mm, None);
        assert!(dataset.warnings.is_empty());
    }

    #[test]
    fn missing_format_is_an_error() {
        let (error, message) = error_of(load_base(&BASE.replace("format = 1\n", "")));
        assert!(matches!(error, DatasetError::Manifest { .. }));
        assert!(
            message.contains("dataset.toml: missing `format`"),
            "{message}"
        );
    }

    #[test]
    fn format_2_is_an_error_with_its_line() {
        let (_, message) = error_of(load_base(&BASE.replace("format = 1", "format = 2")));
        assert!(message.contains("dataset.toml:1:"), "{message}");
        assert!(
            message.contains("`format = 2` is not supported"),
            "{message}"
        );
    }

    #[test]
    fn missing_name_is_an_error() {
        let (_, message) = error_of(load_base(&BASE.replace("name = \"test\"\n", "")));
        assert!(message.contains("dataset.toml"), "{message}");
        assert!(message.contains("missing required `name`"), "{message}");
    }

    #[test]
    fn missing_belt_field_is_an_error() {
        let (_, message) = error_of(load_base(&BASE.replace("mass_kg = 6.4\n", "")));
        assert!(message.contains("dataset.toml:4: [belt]"), "{message}");
        assert!(message.contains("missing required `mass_kg`"), "{message}");
    }

    #[test]
    fn wrong_type_names_file_line_and_field() {
        let (error, message) = error_of(load_base(&BASE.replace("hs_mm = 329", "hs_mm = \"329\"")));
        assert!(
            matches!(error, DatasetError::Manifest { line: Some(12), .. }),
            "{error:?}"
        );
        assert!(message.contains("dataset.toml:12:"), "{message}");
        assert!(message.contains("[[static]] entry 1 (\"a\")"), "{message}");
        assert!(message.contains("`hs_mm` must be a number"), "{message}");
    }

    #[test]
    fn negative_height_names_the_entry() {
        let (_, message) = error_of(load_base(&BASE.replace("hs_mm = 329", "hs_mm = -3")));
        assert!(message.contains("dataset.toml:12:"), "{message}");
        assert!(message.contains("[[static]] entry 1 (\"a\")"), "{message}");
        assert!(message.contains("`hs_mm` must be a finite number greater than 0"));
    }

    #[test]
    fn empty_dataset_is_an_error() {
        let manifest = &BASE[..BASE.find("[[static]]").expect("static")];
        let (error, message) = error_of(load_with(manifest, &[]));
        assert!(matches!(error, DatasetError::EmptyDataset { .. }));
        assert!(message.contains("dataset.toml: empty dataset"), "{message}");
    }

    #[test]
    fn empty_dataset_names_the_last_line() {
        let manifest = &BASE[..BASE.find("[[static]]").expect("static")];
        let last = manifest.trim_end().lines().count();
        let (error, message) = error_of(load_with(manifest, &[]));
        assert!(
            matches!(error, DatasetError::EmptyDataset { line, .. } if line == last),
            "{error:?}"
        );
        assert!(
            message.contains(&format!("dataset.toml:{last}")),
            "{message}"
        );
    }

    #[test]
    fn toml_syntax_error_has_its_line() {
        let (_, message) = error_of(load_base(&BASE.replace("ws_mm = 1068", "ws_mm = = 1")));
        assert!(message.contains("dataset.toml:13:"), "{message}");
    }

    #[test]
    fn single_brackets_for_an_array_are_explained() {
        let (_, message) = error_of(load_base(&BASE.replace("[[static]]", "[static]")));
        assert!(message.contains("dataset.toml:10:"), "{message}");
        assert!(message.contains("double-bracket"), "{message}");
    }

    #[test]
    fn unknown_keys_are_warnings_with_lines() {
        let manifest = BASE
            .replace("name = \"test\"", "name = \"test\"\nrecorded = 2024-05-01")
            .replace("hs_mm = 329", "hs_mm = 329\noperator = { name = \"x\" }");
        let dataset = load_base(&manifest).expect("unknown keys are accepted");
        assert_eq!(dataset.warnings.len(), 2, "{:?}", dataset.warnings);
        assert!(dataset.warnings[0].contains("dataset.toml:3: unknown key `recorded`"));
        assert!(dataset.warnings[1]
            .contains("dataset.toml:14: unknown key `operator` in [[static]] entry 1"));
    }

    #[test]
    fn unknown_keys_in_every_table_are_warnings_with_lines() {
        let manifest = BASE
            .replace("mass_kg = 6.4", "mass_kg = 6.4\ncolour = \"black\"")
            .replace("roller_kg = 1.3", "roller_kg = 1.3\nroller_colour = 3")
            + "\n[[scroll]]\ndrive_diameter_mm = 300\nidler_diameter_mm = 300\n\
               center_distance_mm = 738\nseries = \"dyn.csv\"\nwheel = 1\n";
        let csv = "t_s,omega_rad_s,torque_nm,a_height_mm\n0,1,1,1\n1,1,1,1\n";
        let dataset = load_with(&manifest, &[("dyn.csv", csv)]).expect("load");
        assert_eq!(
            dataset.warnings,
            [
                "dataset.toml:9: unknown key `colour` in [belt]",
                "dataset.toml:18: unknown key `roller_colour` in [[dynamic]] entry 1",
                "dataset.toml:26: unknown key `wheel` in [[scroll]] entry 1",
            ]
            .map(|start| {
                let dir = dataset.dir.join(start);
                format!(
                    "{} ignored (format 1 does not define it; check its spelling)",
                    dir.display()
                )
            })
        );
    }

    #[test]
    fn unknown_keys_in_dotted_and_inline_tables_have_their_lines() {
        let manifest = r#"format = 1
name = "dotted"
belt.length_mm = 2450
belt.width_mm = 160
belt.thickness_mm = 8.5
belt.mass_kg = 6
belt.colour = "black"
static = [ { hs_mm = 329.5, ws_mm = 1068 },
  { hs_mm = 330, ws_mm = 1070, operator = "x" } ]
"#;
        let dataset = load_with(manifest, &[]).expect("load");
        assert_eq!(dataset.warnings.len(), 2, "{:?}", dataset.warnings);
        assert!(dataset.warnings[0].contains("dataset.toml:7: unknown key `colour` in [belt]"));
        assert!(dataset.warnings[1]
            .contains("dataset.toml:9: unknown key `operator` in [[static]] entry 2"));
    }

    #[test]
    fn zero_values_name_file_line_and_field() {
        let (error, message) =
            error_of(load_base(&BASE.replace("roller_kg = 1.3", "roller_kg = 0")));
        assert!(
            matches!(error, DatasetError::Manifest { line: Some(16), .. }),
            "{error:?}"
        );
        assert!(
            message.contains(
                "dataset.toml:16: [[dynamic]] entry 1: `roller_kg` must be a finite number \
                 greater than 0, found 0"
            ),
            "{message}"
        );
        let (_, message) = error_of(load_base(
            &BASE.replace("thickness_mm = 8", "thickness_mm = 0.0"),
        ));
        assert!(
            message.contains("dataset.toml:7: [belt]: `thickness_mm`"),
            "{message}"
        );
    }

    #[test]
    fn missing_entry_field_names_the_entry_header_line() {
        let (error, message) = error_of(load_base(&BASE.replace("ws_mm = 1068\n", "")));
        assert!(
            matches!(error, DatasetError::Manifest { line: Some(10), .. }),
            "{error:?}"
        );
        assert!(
            message
                .contains("dataset.toml:10: [[static]] entry 1 (\"a\"): missing required `ws_mm`"),
            "{message}"
        );
        // A table written with dotted keys is named at its first key.
        let manifest = "format = 1\nname = \"d\"\n\nbelt.length_mm = 2450\nbelt.width_mm = 160\n\
                        belt.mass_kg = 6\nstatic = [ { hs_mm = 1, ws_mm = 2 } ]\n";
        let (_, message) = error_of(load_with(manifest, &[]));
        assert!(
            message.contains("dataset.toml:4: [belt]: missing required `thickness_mm`"),
            "{message}"
        );
    }

    #[test]
    fn an_array_where_a_table_belongs_is_an_error() {
        let belt = "[belt]\nlength_mm = 2450\nwidth_mm = 160.0\nthickness_mm = 8\nmass_kg = 6.4\n";
        let manifest = BASE.replace(belt, "belt = [2450, 160, 8, 6.4]\n");
        let (_, message) = error_of(load_base(&manifest));
        assert!(message.contains("dataset.toml:4:"), "{message}");
        assert!(message.contains("expected the [belt] table"), "{message}");

        let manifest = BASE
            .replace("[[static]]\nlabel = \"a\"\nhs_mm = 329\nws_mm = 1068\n", "")
            .replace("name = \"test\"", "name = \"test\"\nstatic = [[329, 1068]]");
        let (_, message) = error_of(load_base(&manifest));
        assert!(message.contains("dataset.toml:3:"), "{message}");
        assert!(message.contains("expected a [[static]] entry"), "{message}");
    }

    #[test]
    fn other_toml_spellings_are_accepted() {
        let manifest = r#"format = 1
name = "dotted"
belt.length_mm = 2450
belt.width_mm = 160
belt.thickness_mm = 8.5
belt.mass_kg = 6
belt.grousers = 38.0
static = [ { hs_mm = 329.5, ws_mm = 1068 }, { label = "b", hs_mm = 330, ws_mm = 1070 } ]
"#;
        let dataset = load_with(manifest, &[]).expect("load");
        assert_eq!(dataset.belt.mass_kg, 6.0);
        assert_eq!(dataset.belt.grousers, Some(38));
        assert_eq!(dataset.statics.len(), 2);
        assert_eq!(dataset.statics[1].label.as_deref(), Some("b"));
    }

    #[test]
    fn scroll_entry_needs_a_series() {
        let manifest = format!(
            "{BASE}\n[[scroll]]\ndrive_diameter_mm = 300\nidler_diameter_mm = 300\n\
             center_distance_mm = 738\n"
        );
        let (_, message) = error_of(load_base(&manifest));
        assert!(
            message.contains("dataset.toml:19: [[scroll]] entry 1"),
            "{message}"
        );
        assert!(message.contains("missing required `series`"), "{message}");
    }

    #[test]
    fn missing_csv_column_is_an_error() {
        let csv = dyn_csv(|_, row| row).replace("a_height_mm", "height");
        let (error, message) = error_of(load_with(BASE, &[("dyn.csv", &csv)]));
        assert!(matches!(error, DatasetError::Series { .. }));
        assert!(message.contains("dyn.csv:1:"), "{message}");
        assert!(
            message.contains("missing required column `a_height_mm`"),
            "{message}"
        );
    }

    #[test]
    fn bad_row_is_reported_and_skipped() {
        let csv = dyn_csv(|i, row| if i == 3 { "0.12,abc".to_owned() } else { row });
        let dataset = load_with(BASE, &[("dyn.csv", &csv)]).expect("one bad row is allowed");
        let series = dataset.dynamics[0].series.as_ref().expect("series");
        assert_eq!(series.t_s.len(), 29);
        assert_eq!(series.a_height_mm.len(), 29);
        assert!(!series.t_s.contains(&0.12));
        assert_eq!(dataset.warnings.len(), 1, "{:?}", dataset.warnings);
        // Row 3 is the 4th data row: line 5 with the header as line 1.
        let warning = &dataset.warnings[0];
        assert!(warning.contains("dyn.csv:5: "), "{warning}");
        assert!(
            warning.contains("a_height_mm") && warning.contains("skipped"),
            "{warning}"
        );
    }

    #[test]
    fn empty_nonfinite_and_ragged_rows_are_bad() {
        for bad in ["0.12,", "0.12,nan", "inf,3", "0.12,3,4", "0.12"] {
            let csv = dyn_csv(|i, row| if i == 3 { bad.to_owned() } else { row });
            let dataset = load_with(BASE, &[("dyn.csv", &csv)]).expect("load");
            assert_eq!(dataset.warnings.len(), 1, "{bad}: {:?}", dataset.warnings);
            assert!(dataset.warnings[0].contains("dyn.csv:5: "), "{bad}");
        }
    }

    #[test]
    fn more_than_five_percent_bad_rows_is_an_error() {
        // 2 of 30 rows = 6.7 %.
        let csv = dyn_csv(|i, row| {
            if i == 3 || i == 9 {
                "x,y".to_owned()
            } else {
                row
            }
        });
        let (error, message) = error_of(load_with(BASE, &[("dyn.csv", &csv)]));
        assert!(
            matches!(
                error,
                DatasetError::TooManyBadRows {
                    bad: 2,
                    rows: 30,
                    ..
                }
            ),
            "{error:?}"
        );
        assert!(
            message.contains("dyn.csv: 2 of 30 data rows are bad"),
            "{message}"
        );
        assert!(message.contains("line 5"), "{message}");
    }

    #[test]
    fn exactly_five_percent_bad_rows_is_allowed() {
        let mut csv = String::from("t_s,a_height_mm\n");
        for i in 0..20 {
            csv.push_str(&format!("{i},{}\n", if i == 7 { "" } else { "1" }));
        }
        let dataset = load_with(BASE, &[("dyn.csv", &csv)]).expect("1 of 20 is 5 %");
        assert_eq!(dataset.warnings.len(), 1);
    }

    #[test]
    fn non_increasing_time_is_an_error_with_its_line() {
        let csv = dyn_csv(|i, row| if i == 6 { "0.2,290".to_owned() } else { row });
        let (error, message) = error_of(load_with(BASE, &[("dyn.csv", &csv)]));
        assert!(
            matches!(error, DatasetError::Series { line: Some(8), .. }),
            "{error:?}"
        );
        assert!(message.contains("dyn.csv:8:"), "{message}");
        assert!(message.contains("line 7"), "{message}");
    }

    #[test]
    fn csv_without_data_rows_is_an_error() {
        let (_, message) = error_of(load_with(BASE, &[("dyn.csv", "t_s,a_height_mm\n")]));
        assert!(message.contains("dyn.csv: no data rows"), "{message}");
        let (_, message) = error_of(load_with(BASE, &[("dyn.csv", "")]));
        assert!(message.contains("dyn.csv: the file is empty"), "{message}");
    }

    #[test]
    fn missing_csv_file_is_an_error() {
        let (error, message) = error_of(load_with(BASE, &[]));
        assert!(
            matches!(error, DatasetError::MissingSeries { line: 17, .. }),
            "{error:?}"
        );
        assert!(
            message.contains("dyn.csv: series file not found"),
            "{message}"
        );
        assert!(message.contains("dataset.toml:17"), "{message}");
    }

    #[test]
    fn missing_manifest_is_an_io_error() {
        let tmp = TempDir::new("no-manifest");
        let error = load(tmp.path()).expect_err("no manifest");
        assert!(matches!(error, DatasetError::Io { .. }));
        assert!(
            error.to_string().contains("dataset.toml: cannot read"),
            "{error}"
        );
    }

    #[test]
    fn csv_line_numbers_count_blank_lines() {
        let mut csv = String::from("t_s,a_height_mm\n\n0,1\n  \n0.04,x\r\n");
        for i in 2..30 {
            csv.push_str(&format!("{},1\r\n", f64::from(i) * 0.04));
        }
        let dataset = load_with(BASE, &[("dyn.csv", &csv)]).expect("load");
        let series = dataset.dynamics[0].series.as_ref().expect("series");
        assert_eq!(series.t_s.len(), 29);
        assert_eq!(dataset.warnings.len(), 1, "{:?}", dataset.warnings);
        assert!(
            dataset.warnings[0].contains("dyn.csv:5: "),
            "{:?}",
            dataset.warnings
        );
    }

    #[test]
    fn a_value_where_an_array_of_tables_belongs_is_an_error() {
        let manifest = BASE
            .replace("[[static]]\nlabel = \"a\"\nhs_mm = 329\nws_mm = 1068\n", "")
            .replace("name = \"test\"", "name = \"test\"\nstatic = 3");
        let (_, message) = error_of(load_base(&manifest));
        assert!(message.contains("dataset.toml:3:"), "{message}");
        assert!(message.contains("array of tables"), "{message}");
    }
}
