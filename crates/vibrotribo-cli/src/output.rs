//! Writing result files: buffered CSV that is flushed as it goes, and JSON.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use vibrotribo::sweep::Cell;

/// Bytes buffered before a CSV file is written to: long files (a row per event or sample)
/// then cost one system call per 64 KiB instead of per 8 KiB.
const CSV_BUFFER: usize = 1 << 16;

/// A CSV file written row by row.
pub struct CsvFile {
    path: PathBuf,
    out: BufWriter<File>,
    line: Vec<u8>,
    rows: u64,
}

impl CsvFile {
    /// Creates `path` and writes the header `columns`.
    pub fn create(path: &Path, columns: &[impl AsRef<str>]) -> Result<Self> {
        let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
        let mut f = CsvFile {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(CSV_BUFFER, file),
            line: Vec::new(),
            rows: 0,
        };
        let header: Vec<&str> = columns.iter().map(AsRef::as_ref).collect();
        f.out.write_all(header.join(",").as_bytes())?;
        f.out.write_all(b"\n")?;
        Ok(f)
    }

    /// Opens the existing `path`, which holds a header and `rows` rows, to add rows at its end.
    pub fn append(path: &Path, rows: u64) -> Result<Self> {
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .with_context(|| format!("cannot open {} to continue it", path.display()))?;
        Ok(CsvFile {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(CSV_BUFFER, file),
            line: Vec::new(),
            rows,
        })
    }

    /// Rows written (header excluded), those of an appended-to file included.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Writes one row of already-formatted fields. A number that is not finite (NaN, ±inf:
    /// a figure undefined for this row) is written as an empty field.
    pub fn row<I, S>(&mut self, fields: I) -> Result<()>
    where
        I: IntoIterator<Item = S>,
        S: std::fmt::Display,
    {
        self.line.clear();
        for (i, f) in fields.into_iter().enumerate() {
            if i > 0 {
                self.line.push(b',');
            }
            let start = self.line.len();
            let _ = write!(self.line, "{f}");
            if matches!(&self.line[start..], b"NaN" | b"inf" | b"-inf") {
                self.line.truncate(start);
            }
        }
        self.line.push(b'\n');
        self.rows += 1;
        self.out
            .write_all(&self.line)
            .with_context(|| format!("cannot write {}", self.path.display()))
    }

    /// Writes one row whose fields `fill` appends through [`Fields`] (numbers laid out as
    /// `Display` would, without its cost: the writer of the long per-event and per-sample files).
    pub fn row_with(&mut self, fill: impl FnOnce(&mut Fields<'_>)) -> Result<()> {
        self.line.clear();
        fill(&mut Fields {
            line: &mut self.line,
            first: true,
        });
        self.line.push(b'\n');
        self.rows += 1;
        self.out
            .write_all(&self.line)
            .with_context(|| format!("cannot write {}", self.path.display()))
    }

    /// Flushes to disk.
    pub fn flush(&mut self) -> Result<()> {
        self.out
            .flush()
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// The fields of one row being written ([`CsvFile::row_with`]), as [`CsvFile::row`] writes them:
/// a number that is not finite is an empty field.
pub struct Fields<'a> {
    line: &'a mut Vec<u8>,
    first: bool,
}

impl Fields<'_> {
    fn separate(&mut self) {
        if !self.first {
            self.line.push(b',');
        }
        self.first = false;
    }

    /// A number, as `format!("{x}")` writes it (empty if not finite).
    pub fn number(&mut self, x: f64) {
        self.separate();
        crate::decimal::push_f64(self.line, x);
    }

    /// Numbers, one field each.
    pub fn numbers(&mut self, xs: &[f64]) {
        for &x in xs {
            self.number(x);
        }
    }

    /// A field of text (written as it is).
    pub fn text(&mut self, s: &str) {
        self.separate();
        self.line.extend_from_slice(s.as_bytes());
    }

    /// An integer.
    pub fn integer(&mut self, i: u64) {
        self.separate();
        let _ = write!(self.line, "{i}");
    }
}

/// Writes a CSV file of the header `names` and the rows `rows` of the library's table writer
/// (each cell a CSV field).
pub fn write_rows(
    path: &Path,
    names: &[impl AsRef<str>],
    rows: impl IntoIterator<Item = Vec<vibrotribo::sweep::Cell>>,
) -> Result<()> {
    let mut csv = CsvFile::create(path, names)?;
    for row in rows {
        csv.row(row)?;
    }
    csv.flush()
}

/// Writes `value` as pretty JSON to `path`, atomically: a reader (or a later run after a
/// kill) sees either the old file or the new one, never a part of one.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    write_atomic(path, text.as_bytes())
}

/// Writes `bytes` to `path` through a temporary file in the same directory renamed over it.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let name = path
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let write = || -> std::io::Result<()> {
        let mut f = File::create(&tmp)?;
        f.write_all(bytes)?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::Error::from(e).context(format!("cannot write {}", path.display()))
    })
}

/// Reads the JSON file `path`.
pub fn read_json(path: &Path) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not valid JSON", path.display()))
}

/// The manifests by which a directory is known to hold a command's results.
pub const MANIFESTS: [&str; 13] = [
    "summary.json",
    "sweep.json",
    "map.json",
    "basins.json",
    "attractors.json",
    "chirp.json",
    "continue.json",
    "load_sweep.json",
    "lyapunov.json",
    "periodic.json",
    "response.json",
    "band_response.json",
    "bifmap.json",
];

/// Refuses to write a job's results into `dir` when it holds another job's: a manifest
/// other than `manifest`, or `manifest` itself with other settings (`same` false), unless
/// `force` (files of the same name are then replaced, the others left as they are).
pub fn check_out_dir(
    dir: &Path,
    manifest: &str,
    force: bool,
    same: impl Fn(&serde_json::Value) -> bool,
) -> Result<()> {
    if force {
        return Ok(());
    }
    for name in MANIFESTS {
        let path = dir.join(name);
        if !path.exists() {
            continue;
        }
        let other = name != manifest || read_json(&path).map_or(true, |old| !same(&old));
        if other {
            anyhow::bail!(
                "{} holds the results of another job ({name}); write into a new directory, continue \
                 that job with --resume, or pass --force to write over it",
                dir.display()
            );
        }
    }
    Ok(())
}

/// Creates `dir` (and parents) for output.
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create output directory {}", dir.display()))
}

/// Column names `prefix1suffix, …, prefixNsuffix`.
pub fn numbered(prefix: &str, n: usize, suffix: &str) -> Vec<String> {
    (1..=n).map(|i| format!("{prefix}{i}{suffix}")).collect()
}

/// Complex multipliers as text, `re±imi` each, space-separated, numbers written exactly (a
/// CSV cell after [`csv_text`]).
pub fn multipliers_text(multipliers: &[vibrotribo::nalgebra::Complex<f64>]) -> String {
    multipliers
        .iter()
        .map(|m| format!("{}{:+}i", m.re, m.im))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A text field for CSV: quoted (with quotes doubled) if it holds a comma, quote or newline
/// (the library's [`Cell`] text).
pub fn csv_text(text: &str) -> String {
    Cell::Text(text.to_string()).to_string()
}

/// Reads a CSV file written by this program: header and rows of fields (quoted fields are
/// kept whole).
pub fn read_csv(path: &Path) -> Result<(Vec<String>, Vec<Vec<String>>)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| anyhow::anyhow!("{} is empty", path.display()))?
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines.map(split_csv_line).collect();
    Ok((header, rows))
}

fn split_csv_line(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    out.push(field);
    out
}

/// Column `name` of `header`, or an error naming the file's columns.
pub fn column(header: &[String], name: &str) -> Result<usize> {
    header
        .iter()
        .position(|h| h == name)
        .ok_or_else(|| anyhow::anyhow!("no column `{name}` (columns: {})", header.join(", ")))
}

/// Column `idx` of `rows` parsed as numbers (empty or unparsable fields become NaN).
pub fn numbers(rows: &[Vec<String>], idx: usize) -> Vec<f64> {
    rows.iter()
        .map(|r| r.get(idx).and_then(|f| f.parse().ok()).unwrap_or(f64::NAN))
        .collect()
}

/// `value` with an SI prefix and `unit`, 4 significant digits (`12.92 µW`).
pub fn si(value: f64, unit: &str) -> String {
    if !value.is_finite() {
        return format!("undefined ({unit})");
    }
    if value == 0.0 {
        return format!("0 {unit}");
    }
    const PREFIXES: [(f64, &str); 11] = [
        (1e12, "T"),
        (1e9, "G"),
        (1e6, "M"),
        (1e3, "k"),
        (1.0, ""),
        (1e-3, "m"),
        (1e-6, "µ"),
        (1e-9, "n"),
        (1e-12, "p"),
        (1e-15, "f"),
        (1e-18, "a"),
    ];
    let a = value.abs();
    let (scale, prefix) = PREFIXES
        .iter()
        .copied()
        .find(|(s, _)| a >= *s)
        .unwrap_or(PREFIXES[PREFIXES.len() - 1]);
    let x = value / scale;
    let digits = if x.abs() >= 100.0 {
        1
    } else if x.abs() >= 10.0 {
        2
    } else {
        3
    };
    format!("{x:.digits$} {prefix}{unit}")
}

#[cfg(test)]
mod tests {
    #[test]
    fn csv_fields_round_trip() {
        let text = super::csv_text("stopped, at t = 1: \"event limit\"");
        assert_eq!(
            super::split_csv_line(&format!("1.5,,{text}")),
            ["1.5", "", "stopped, at t = 1: \"event limit\""]
        );
    }

    #[test]
    fn si_prefixes() {
        assert_eq!(super::si(1.292e-5, "W"), "12.92 µW");
        assert_eq!(super::si(1e5, "Ω"), "100.0 kΩ");
        assert_eq!(super::si(0.0, "A"), "0 A");
        assert_eq!(super::si(-2.5e-9, "C"), "-2.500 nC");
    }
}
