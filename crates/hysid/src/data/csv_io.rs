//! Reading and writing identification data as CSV files.
//!
//! Files have a header row; columns are picked by name (exact match first, then
//! case-insensitive). Cells and header names may carry leading and trailing spaces, and a
//! UTF-8 byte-order mark is accepted. Only the requested columns are parsed, so a file may
//! hold other, non-numeric columns.
//!
//! Every error is one line and names the file. Errors about a row give its one-based line
//! number in the file, except [`Error::NonFinite`] (a cell reading `nan`, `inf`, ...),
//! which names the column as `channel` and the zero-based data-row index as `index`: for a
//! file without blank lines or multi-line quoted cells, that is the line number minus two.
//!
//! Long files of plain rows (one per line, no quotes) are read in parallel chunks; any other
//! file, and any file with a bad row, is read record by record. Both give the same values,
//! bit for bit, and the same errors.

use std::fmt::Write as _;
use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};

use csv::{ByteRecord, ErrorKind, ReaderBuilder};

use super::{one_line, Channel, Experiment, IdData};
use crate::error::{Error, Result};
use crate::io::atomic::OutputSet;

/// Names (compared case-insensitively) recognised as a time column when the spec names none.
pub(super) const TIME_COLUMN_NAMES: [&str; 4] = ["t", "time", "t_s", "time_s"];

/// Largest relative deviation of a time step from the mean step that is still "uniform".
const TIME_STEP_RTOL: f64 = 0.01;

/// Which columns of a CSV file to read, and how to get the sample time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CsvSpec {
    /// Names of the input columns.
    pub inputs: Vec<String>,
    /// Names of the output columns.
    pub outputs: Vec<String>,
    /// Name of the time column, if the file has one that is not called `t`, `time`, `t_s`
    /// or `time_s`.
    pub time: Option<String>,
    /// Sample time; when given, any time column is ignored.
    pub ts: Option<f64>,
    /// What a time column's steps must be: uniform (the default, for every model with
    /// dynamics in time) or only increasing (the rate-independent hysteresis of the zoo).
    pub time_steps: TimeSteps,
}

/// What a time column's steps must be ([`CsvSpec::time_steps`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeSteps {
    /// Strictly increasing and uniform: the sample time is the mean step, and no step may
    /// differ from it by more than 1 %.
    #[default]
    Uniform,
    /// Strictly increasing only, the samples in time order: the set points of a
    /// rate-independent model (the hysteresis operators, whose output depends on the
    /// sequence of inputs, not on when they came), taken at irregular moments or in several
    /// runs with gaps between them. The sample time is the median step, a label for the
    /// reports and the time axis of written records; it does not enter the model.
    Ordered,
}

impl TimeSteps {
    /// The sample time of the time column `time` under this rule; else the zero-based index
    /// of the first offending sample and what is wrong there.
    pub(super) fn sample_time(self, time: &[f64]) -> std::result::Result<f64, (usize, String)> {
        match self {
            TimeSteps::Uniform => uniform_step(time),
            TimeSteps::Ordered => median_step(time),
        }
    }

    /// What to do about a time column (`what`: "column" or "variable") this rule refuses.
    pub(super) fn hint(self, what: &str) -> String {
        match self {
            TimeSteps::Uniform => format!(
                "resample the data to a uniform grid, or pass --ts to set the sample time and \
                 ignore the time {what}"
            ),
            TimeSteps::Ordered => format!(
                "put the rows in time order on one clock (runs whose clock restarts at 0 \
                 continue the previous run's time), or pass --ts to ignore the time {what}"
            ),
        }
    }
}

impl IdData {
    /// Reads one experiment from a CSV file, named after the file's stem.
    ///
    /// Channels are the spec's input and output columns, named as in the file's header.
    /// The sample time is, in order of preference: `spec.ts`; the time column `spec.time`;
    /// a column named `t`, `time`, `t_s` or `time_s` (any case; the first one that is not
    /// an input or output); otherwise 1.0, i.e. time in samples. A time column must be
    /// strictly increasing and, under the default [`TimeSteps::Uniform`], uniform: the
    /// sample time is its mean step, and no step may differ from it by more than 1 %
    /// ([`TimeSteps::Ordered`]: only increasing, the median step). See the
    /// [module documentation](self) for errors.
    ///
    /// ```
    /// use hysid::data::{CsvSpec, IdData};
    ///
    /// let dir = tempfile::tempdir()?;
    /// let path = dir.path().join("run.csv");
    /// std::fs::write(&path, "time,u,y,note\n0.0,1.0,0.5,start\n0.1,2.0,1.5,\n0.2,3.0,2.5,end\n")?;
    ///
    /// let spec = CsvSpec {
    ///     inputs: vec!["u".into()],
    ///     outputs: vec!["y".into()],
    ///     ..CsvSpec::default()
    /// };
    /// let data = IdData::from_csv(&path, &spec)?;
    /// assert!((data.ts() - 0.1).abs() < 1e-12);
    /// assert_eq!(data.input(0, 0), &[1.0, 2.0, 3.0]);
    /// assert_eq!(data.experiment(0).name(), "run");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_csv(path: &Path, spec: &CsvSpec) -> Result<IdData> {
        if spec.inputs.is_empty() && spec.outputs.is_empty() {
            return Err(Error::InvalidData(format!(
                "{}: no input or output columns were asked for",
                path.display()
            )));
        }
        let mut table = Table::open(path)?;
        let channel_columns = spec
            .inputs
            .iter()
            .chain(&spec.outputs)
            .map(|name| table.find(name))
            .collect::<Result<Vec<_>>>()?;
        let time_column = match (spec.ts, &spec.time) {
            (Some(_), _) => None,
            (None, Some(name)) => Some(table.find(name)?),
            (None, None) => table.detect_time_column(&channel_columns),
        };

        let mut wanted = channel_columns.clone();
        wanted.extend(time_column);
        let mut columns = table.read(&wanted)?;
        let ts = match (spec.ts, time_column) {
            (Some(ts), _) => ts,
            (None, Some(col)) => {
                let time = columns.pop().expect("the time column was read last");
                sample_time(path, &table.header[col], &time, spec.time_steps)?
            }
            (None, None) => 1.0,
        };

        let outputs = columns.split_off(spec.inputs.len());
        let channel = |&col: &usize| Channel::new(table.header[col].clone());
        let (input_columns, output_columns) = channel_columns.split_at(spec.inputs.len());
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        let experiment = Experiment::new(name, columns, outputs)?;
        let inputs = input_columns.iter().map(channel).collect();
        let outputs = output_columns.iter().map(channel).collect();
        // What can still go wrong here (a column asked for twice, a bad spec.ts) is about
        // this file too: say which.
        IdData::new(ts, inputs, outputs, vec![experiment]).map_err(|error| match error {
            Error::InvalidData(message) => {
                Error::InvalidData(format!("{}: {message}", path.display()))
            }
            other => other,
        })
    }

    /// Writes a single-experiment data set: a column `t` (k·ts) then every input and output
    /// channel, in full precision (see [`write_csv`]). A record read under
    /// [`TimeSteps::Ordered`] is written on the uniform grid of its median step: its own
    /// irregular times are not kept.
    ///
    /// Reading the file back with [`IdData::from_csv`] restores the samples bit-exactly and
    /// the sample time up to rounding (pass [`CsvSpec::ts`] to restore it exactly).
    ///
    /// Fails with [`Error::InvalidData`] if the data set has several experiments (write them
    /// one at a time with [`write_csv`]) or a channel is itself called `t`.
    pub fn to_csv(&self, path: &Path) -> Result<()> {
        let [experiment] = self.experiments.as_slice() else {
            return Err(Error::InvalidData(format!(
                "{}: to_csv writes one experiment but this data set has {}; \
                 write them one at a time with write_csv",
                path.display(),
                self.experiments.len()
            )));
        };
        let channels = self.inputs.iter().chain(&self.outputs);
        if channels.clone().any(|c| c.name == "t") {
            return Err(Error::InvalidData(format!(
                "{}: a channel is called 't', the name of the time column; rename it",
                path.display()
            )));
        }
        let time: Vec<f64> = (0..experiment.len()).map(|k| k as f64 * self.ts).collect();
        let headers: Vec<&str> = std::iter::once("t")
            .chain(channels.map(|c| c.name.as_str()))
            .collect();
        let columns: Vec<&[f64]> = std::iter::once(time.as_slice())
            .chain(experiment.inputs.iter().map(Vec::as_slice))
            .chain(experiment.outputs.iter().map(Vec::as_slice))
            .collect();
        write_csv(path, &headers, &columns)
    }
}

/// Reads the named columns of a CSV file: returns the header (trimmed) and one vector per
/// name, in the order asked for.
///
/// Names are matched exactly first, then case-insensitively; a name that matches several
/// columns is an error. See the [module documentation](self) for errors.
pub fn read_columns(path: &Path, names: &[&str]) -> Result<(Vec<String>, Vec<Vec<f64>>)> {
    let (header, columns, _) = read_columns_by(path, names, Rows::Auto)?;
    Ok((header, columns))
}

/// Which way [`read_columns_by`] reads the rows.
#[doc(hidden)] // reached by the white-box tests (crates/hysid-tests) and the csv bench
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rows {
    /// As [`read_columns`]: in parallel chunks when the file is long, rayon has two threads
    /// or more and the platform has positioned reads; else sequentially.
    Auto,
    /// Sequentially (csv records), whatever the file.
    Sequential,
    /// In chunks of this many bytes whatever the file's length and the number of threads,
    /// falling back to the sequential path as usual.
    Chunked(usize),
}

/// [`read_columns`] the given way; also says whether the chunks read the rows (true) or the
/// sequential path (false).
#[doc(hidden)] // reached by the white-box tests (crates/hysid-tests) and the csv bench
pub fn read_columns_by(
    path: &Path,
    names: &[&str],
    rows: Rows,
) -> Result<(Vec<String>, Vec<Vec<f64>>, bool)> {
    let mut table = Table::open(path)?;
    let indices = names
        .iter()
        .map(|name| table.find(name))
        .collect::<Result<Vec<_>>>()?;
    let (columns, chunked) = table.read_by(&indices, rows)?;
    Ok((table.header, columns, chunked))
}

/// Writes `columns` under `headers` as a CSV file, replacing `path` atomically through the
/// library's one writer, [`crate::io::atomic::OutputSet`]: the data go to a temporary file
/// in the same directory, which is renamed over `path` once complete.
///
/// Values are written in full precision (shortest text that reads back to the same `f64`;
/// scientific notation for very large or small magnitudes), so reading them back is
/// bit-exact. Fails with [`Error::InvalidData`] if there is no column, the numbers of
/// headers and columns differ or the columns differ in length, with [`Error::NonFinite`] on
/// a NaN or infinite value (it could not be read back), and with [`Error::Io`] if the file
/// cannot be written.
pub fn write_csv(path: &Path, headers: &[&str], columns: &[&[f64]]) -> Result<()> {
    check_table(path, headers, columns)?;
    let io_error = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut output = OutputSet::new(&[])?;
    let temp = output.file(path)?;
    let file = crate::io::atomic::create(&temp)?;
    write_table(file, headers, columns).map_err(io_error)?;
    output.commit()
}

/// A CSV file opened for reading, positioned after its header.
struct Table {
    path: PathBuf,
    reader: csv::Reader<File>,
    /// Trimmed column names.
    header: Vec<String>,
}

impl Table {
    fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        // csv strips a UTF-8 byte-order mark and, by default, insists on equal-length rows.
        let mut reader = ReaderBuilder::new().has_headers(true).from_reader(file);
        let header: Vec<String> = reader
            .byte_headers()
            .map_err(|e| csv_error(path, e))?
            .iter()
            .map(|name| String::from_utf8_lossy(name.trim_ascii()).into_owned())
            .collect();
        if header.is_empty() {
            return Err(Error::InvalidData(format!(
                "{}: empty file; expected a header row followed by data rows",
                path.display()
            )));
        }
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            header,
        })
    }

    /// Index of the column called `name`: the exact match, else the case-insensitive one.
    fn find(&self, name: &str) -> Result<usize> {
        let name = name.trim();
        let matching = |same: &dyn Fn(&str) -> bool| -> Vec<usize> {
            (0..self.header.len())
                .filter(|&i| same(&self.header[i]))
                .collect()
        };
        let mut found = matching(&|h| h == name);
        if found.is_empty() {
            let lower = name.to_lowercase();
            found = matching(&|h| h.to_lowercase() == lower);
        }
        match found.as_slice() {
            [index] => Ok(*index),
            [] => Err(Error::MissingColumn {
                path: self.path.clone(),
                column: one_line(name).into_owned(),
                available: one_line(&self.header.join(", ")).into_owned(),
            }),
            several => {
                let positions: Vec<String> = several.iter().map(|i| (i + 1).to_string()).collect();
                Err(Error::InvalidData(format!(
                    "{}: column name '{}' is ambiguous: columns {} all match; rename them",
                    self.path.display(),
                    one_line(name),
                    positions.join(", ")
                )))
            }
        }
    }

    /// The first column with a conventional time name that is not in `taken`.
    fn detect_time_column(&self, taken: &[usize]) -> Option<usize> {
        (0..self.header.len()).find(|i| {
            let name = self.header[*i].to_lowercase();
            TIME_COLUMN_NAMES.contains(&name.as_str()) && !taken.contains(i)
        })
    }

    /// Parses the given columns of every remaining row.
    fn read(&mut self, indices: &[usize]) -> Result<Vec<Vec<f64>>> {
        Ok(self.read_by(indices, Rows::Auto)?.0)
    }

    /// [`Self::read`] the given way: the columns, and whether the chunks read them.
    fn read_by(&mut self, indices: &[usize], rows: Rows) -> Result<(Vec<Vec<f64>>, bool)> {
        match self.read_chunks(indices, rows) {
            Some(columns) => Ok((columns, true)),
            None => Ok((self.read_records(indices)?, false)),
        }
    }

    /// The columns read by [`chunks`], or None when that path does not apply or gives up;
    /// the csv reader is left after the header either way.
    #[cfg(unix)]
    fn read_chunks(&self, indices: &[usize], rows: Rows) -> Option<Vec<Vec<f64>>> {
        let (chunk_bytes, min_bytes) = match rows {
            Rows::Auto if rayon::current_num_threads() >= 2 => {
                (chunks::CHUNK_BYTES, chunks::MIN_BYTES)
            }
            Rows::Chunked(chunk_bytes) => (chunk_bytes, 0),
            Rows::Auto | Rows::Sequential => return None,
        };
        chunks::read(
            self.reader.get_ref(),
            self.reader.position().byte(),
            self.header.len(),
            indices,
            chunk_bytes,
            min_bytes,
        )
    }

    /// Without positioned reads, every file takes the sequential path.
    #[cfg(not(unix))]
    fn read_chunks(&self, _indices: &[usize], _rows: Rows) -> Option<Vec<Vec<f64>>> {
        None
    }

    /// Parses the given columns of every remaining csv record: the sequential path, which
    /// reads any file and gives every error.
    fn read_records(&mut self, indices: &[usize]) -> Result<Vec<Vec<f64>>> {
        let mut columns = vec![Vec::new(); indices.len()];
        // Records are reused batch after batch: no allocation per row.
        let mut row = 0;
        let Self {
            path,
            reader,
            header,
        } = self;
        pipeline::for_each_batch(reader, |records| {
            for record in records {
                for (&col, column) in indices.iter().zip(&mut columns) {
                    column.push(Self::parse_cell(path, header, record, col, row)?);
                }
                row += 1;
            }
            Ok::<(), Error>(())
        })
        .map_err(|e| csv_error(path, e))??;
        if row == 0 {
            return Err(Error::InvalidData(format!(
                "{}: no data rows below the header",
                self.path.display()
            )));
        }
        Ok(columns)
    }

    fn parse_cell(
        path: &Path,
        header: &[String],
        record: &ByteRecord,
        col: usize,
        row: usize,
    ) -> Result<f64> {
        let cell = record.get(col).unwrap_or_default().trim_ascii();
        let value = number(cell).ok_or_else(|| Error::NotNumeric {
            path: path.to_path_buf(),
            line: record.position().map_or(0, |p| p.line()),
            column: one_line(&header[col]).into_owned(),
            text: one_line(&String::from_utf8_lossy(cell)).into_owned(),
        })?;
        if !value.is_finite() {
            return Err(Error::NonFinite {
                channel: one_line(&header[col]).into_owned(),
                index: row,
                value,
            });
        }
        Ok(value)
    }
}

/// The number a trimmed cell holds, if any: the one parser of both reading paths, so that
/// they give the same bits. Most cells take the exact fast path; the rest (and every error)
/// the full parser.
fn number(cell: &[u8]) -> Option<f64> {
    float::parse_fast(cell).or_else(|| std::str::from_utf8(cell).ok()?.parse::<f64>().ok())
}

/// The sample time of a time column under `steps` ([`TimeSteps`]).
fn sample_time(path: &Path, column: &str, time: &[f64], steps: TimeSteps) -> Result<f64> {
    let column = one_line(column);
    steps.sample_time(time).map_err(|(row, problem)| {
        Error::InvalidData(format!(
            "{}: line {}: time column '{column}' {problem}; {}",
            path.display(),
            line_of_row(path, row),
            steps.hint("column")
        ))
    })
}

/// Errors unless the time vector has two values or more and strictly increases: the
/// zero-based index of the first offending sample and what is wrong there.
fn increasing(time: &[f64]) -> std::result::Result<(), (usize, String)> {
    if time.len() < 2 {
        return Err((0, "has a single value, which gives no sample time".into()));
    }
    match time.windows(2).position(|pair| pair[1] <= pair[0]) {
        Some(k) => Err((
            k + 1,
            format!(
                "is not strictly increasing ({} follows {})",
                time[k + 1],
                time[k]
            ),
        )),
        None => Ok(()),
    }
}

/// The median step of a strictly increasing time vector ([`TimeSteps::Ordered`]): the
/// middle one, or the mean of the two middle ones.
fn median_step(time: &[f64]) -> std::result::Result<f64, (usize, String)> {
    increasing(time)?;
    let mut steps: Vec<f64> = time.windows(2).map(|pair| pair[1] - pair[0]).collect();
    steps.sort_by(f64::total_cmp);
    let half = steps.len() / 2;
    Ok(if steps.len() % 2 == 1 {
        steps[half]
    } else {
        0.5 * (steps[half - 1] + steps[half])
    })
}

/// The mean step of a strictly increasing, uniform time vector; else the zero-based index
/// of the first offending sample and what is wrong there.
pub(super) fn uniform_step(time: &[f64]) -> std::result::Result<f64, (usize, String)> {
    // Monotonicity first: a step back would otherwise show up as a misleading "bad step".
    increasing(time)?;
    let ts = (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64;
    let off = |pair: &[f64]| (pair[1] - pair[0] - ts).abs() > TIME_STEP_RTOL * ts;
    if let Some(k) = time.windows(2).position(off) {
        let step = time[k + 1] - time[k];
        return Err((
            k + 1,
            format!("has a step of {step}, more than 1 % off the mean step {ts}"),
        ));
    }
    Ok(ts)
}

/// One-based line number of data row `row` (zero-based), for error messages.
///
/// Found by reading the file again: rows and lines differ when there are blank lines or
/// multi-line quoted cells, and remembering every row's line would cost memory on the
/// success path for the benefit of the error path.
fn line_of_row(path: &Path, row: usize) -> u64 {
    let line = || -> Option<u64> {
        let mut reader = ReaderBuilder::new().from_path(path).ok()?;
        let mut record = ByteRecord::new();
        for _ in 0..=row {
            if !reader.read_byte_record(&mut record).ok()? {
                return None;
            }
        }
        Some(record.position()?.line())
    };
    // The file was read successfully a moment ago; should it have changed since, the usual
    // layout (header on line 1, one row per line) is the best guess left.
    line().unwrap_or(row as u64 + 2)
}

fn csv_error(path: &Path, error: csv::Error) -> Error {
    let line = error.position().map_or(0, |p| p.line());
    let message = one_line(&error.to_string()).into_owned();
    match error.into_kind() {
        ErrorKind::Io(source) => Error::Io {
            path: path.to_path_buf(),
            source,
        },
        ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => Error::Csv {
            path: path.to_path_buf(),
            line,
            message: format!(
                "row has {len} fields but the header has {expected_len}; \
                 every row needs one field per column"
            ),
        },
        // The reader's own text carries its position record ("(line: 3, byte: 20)"): the
        // line is in the error already, the rest is said in words.
        ErrorKind::Utf8 { err, .. } => Error::Csv {
            path: path.to_path_buf(),
            line,
            message: format!(
                "field {} is not valid UTF-8 text; save the file as UTF-8 (or plain ASCII)",
                err.field() + 1
            ),
        },
        _ => Error::Csv {
            path: path.to_path_buf(),
            line,
            message: format!(
                "cannot be read as CSV ({}); save it as comma-separated text with a header row",
                message
                    .split_once("): ")
                    .map_or(message.as_str(), |(_, what)| what)
            ),
        },
    }
}

fn check_table(path: &Path, headers: &[&str], columns: &[&[f64]]) -> Result<()> {
    let invalid = |problem: String| Error::InvalidData(format!("{}: {problem}", path.display()));
    if columns.is_empty() {
        return Err(invalid("nothing to write: no columns".into()));
    }
    if headers.len() != columns.len() {
        return Err(invalid(format!(
            "{} headers for {} columns; give one header per column",
            headers.len(),
            columns.len()
        )));
    }
    let rows = columns[0].len();
    for (header, column) in headers.iter().zip(columns) {
        if column.len() != rows {
            return Err(invalid(format!(
                "column '{}' has {} values but column '{}' has {rows}; \
                 all columns must have the same length",
                one_line(header),
                column.len(),
                one_line(headers[0])
            )));
        }
        // A table being written holds results: a non-finite one is a numerical failure,
        // not bad data.
        if let Some(index) = column.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFiniteResult {
                key: format!("{}[{index}]", one_line(header)),
                value: column[index],
            });
        }
    }
    Ok(())
}

fn write_table(file: File, headers: &[&str], columns: &[&[f64]]) -> io::Result<()> {
    let mut writer = csv::Writer::from_writer(file);
    writer.write_record(headers)?;
    let mut record = ByteRecord::new();
    let mut cell = String::new();
    for row in 0..columns[0].len() {
        record.clear();
        for column in columns {
            cell.clear();
            push_f64(&mut cell, column[row]);
            record.push_field(cell.as_bytes());
        }
        writer.write_byte_record(&record)?;
    }
    let file = writer.into_inner().map_err(|e| e.into_error())?;
    // Make the data durable before the rename makes them visible.
    file.sync_all()
}

/// Appends the shortest text that parses back to exactly `value`.
fn push_f64(out: &mut String, value: f64) {
    // Plain `{}` never uses an exponent, which would spell 1e-300 with 300 zeros.
    let plain = value == 0.0 || (1e-5..1e16).contains(&value.abs());
    let written = if plain {
        write!(out, "{value}")
    } else {
        write!(out, "{value:e}")
    };
    written.expect("writing to a String cannot fail");
}

#[cfg(unix)]
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod chunks;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod float;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod pipeline;
