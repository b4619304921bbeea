//! Output directories of grid jobs (sweeps, maps, and their shards): a manifest that says
//! what the directory holds and whether it is complete, resuming an interrupted job, and
//! merging shards.
//!
//! The protocol, which makes every state of a directory either usable or recognisably
//! unfinished:
//!
//! 1. A fresh job writes its manifest (`sweep.json`, `map.json`: the settings that determine
//!    the output) with `"complete": false` *before* any row, then creates its CSV files.
//! 2. Rows are written point by point in grid order. A point's *index row* (its row of
//!    `summary.csv` or `map.csv`) is held back until [`GridOutput::commit`], which flushes
//!    every other file first: an index row on disk means that all the point's rows are.
//! 3. At the end the manifest is rewritten atomically with `"complete": true` and the number
//!    of rows of every file (`"rows"`). An interrupted job rewrites it with
//!    `"complete": false` and the number of points finished (`"done"`).
//!
//! `--resume` reads the manifest, checks that the settings are the same, counts the points
//! whose index row is whole (a line ends with a newline), truncates every file to the rows
//! of those points (dropping the partial rows of the point that was cut), and continues; the
//! result is byte-identical to an uninterrupted run. `merge` checks that every shard is
//! complete, that its files hold the rows its manifest counts, and that every grid point is
//! present exactly once, and writes into a temporary directory renamed into place.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use serde_json::{Value, json};

use crate::output::{CsvFile, check_out_dir, create_dir, read_json, write_atomic, write_json};

/// Manifest keys that describe the progress of a directory rather than its settings.
const PROGRESS_KEYS: [&str; 3] = ["complete", "done", "rows"];

/// One CSV file of a grid job.
#[derive(Debug, Clone)]
pub struct CsvSpec {
    /// File name, e.g. `orbit.csv`.
    pub name: &'static str,
    /// Header columns.
    pub columns: Vec<String>,
}

/// The shape of a grid job's directory.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Manifest file name (`sweep.json`, `map.json`).
    pub manifest: &'static str,
    /// The CSV files.
    pub files: Vec<CsvSpec>,
    /// Index into `files` of the file with exactly one row per finished point, written last.
    pub index_file: usize,
    /// Leading fields of a row that name its point (1 for a sweep's value, 2 for a map's x, y).
    pub key_fields: usize,
}

/// An open grid-job directory.
pub struct GridOutput {
    dir: PathBuf,
    layout: Layout,
    settings: Value,
    files: Vec<CsvFile>,
    /// Index rows waiting for [`commit`](GridOutput::commit).
    pending: Vec<Vec<String>>,
}

/// The key of a CSV line: its first `fields` fields (keys are numbers, never quoted).
fn line_key(line: &str, fields: usize) -> &str {
    let mut end = 0;
    for (i, part) in line.split(',').take(fields).enumerate() {
        end += part.len() + usize::from(i > 0);
    }
    &line[..end.min(line.len())]
}

/// The whole lines of a file after its header, with the byte offset just past each.
fn whole_lines(text: &str) -> (usize, Vec<(&str, usize)>) {
    let header_end = text.find('\n').map_or(text.len(), |i| i + 1);
    let mut out = Vec::new();
    let mut pos = header_end;
    while let Some(i) = text[pos..].find('\n') {
        out.push((&text[pos..pos + i], pos + i + 1));
        pos += i + 1;
    }
    (header_end, out)
}

/// The manifest without its progress keys and with `shard` null (in its place, so that the
/// key order is that of an unsharded job): what the shards of one job share.
fn settings_of(manifest: &Value) -> Value {
    let mut s = manifest.clone();
    if let Some(o) = s.as_object_mut() {
        for k in PROGRESS_KEYS {
            o.shift_remove(k);
        }
        if let Some(shard) = o.get_mut("shard") {
            *shard = Value::Null;
        }
    }
    s
}

impl GridOutput {
    /// Starts a fresh job in `dir`: the manifest `settings` marked incomplete, then empty
    /// CSV files with their headers.
    /// A directory that holds another job's results is refused unless `force`.
    pub fn create(dir: &Path, layout: Layout, settings: Value, force: bool) -> Result<Self> {
        check_out_dir(dir, layout.manifest, force, |old| {
            settings_of(old) == settings_of(&settings) && old.get("shard") == settings.get("shard")
        })?;
        create_dir(dir)?;
        let mut out = GridOutput {
            dir: dir.to_path_buf(),
            layout,
            settings,
            files: Vec::new(),
            pending: Vec::new(),
        };
        out.write_manifest(false, 0)?;
        let _ = std::fs::remove_file(dir.join(CHECKPOINT));
        for spec in &out.layout.files {
            out.files
                .push(CsvFile::create(&dir.join(spec.name), &spec.columns)?);
        }
        out.flush()?;
        Ok(out)
    }

    /// Continues the job in `dir` whose points, in grid order, have the keys `keys`, keeping
    /// at most `keep_at_most` finished points (a continuation keeps those its checkpoint
    /// covers). Returns the directory, open for appending, and how many points are kept; an
    /// error if the directory holds another job or files that do not fit the protocol.
    pub fn resume(
        dir: &Path,
        layout: Layout,
        settings: Value,
        keys: &[String],
        keep_at_most: usize,
    ) -> Result<(Self, usize)> {
        let manifest_path = dir.join(layout.manifest);
        let old = read_json(&manifest_path).with_context(|| {
            format!(
                "--resume: {} holds no job to resume (run without --resume to start one)",
                dir.display()
            )
        })?;
        let (a, b) = (settings_of(&old), settings_of(&settings));
        if a != b || old.get("shard") != settings.get("shard") {
            bail!(
                "--resume: {} holds a different job (its {} has other settings); \
                 resume with the same configuration and options, or start afresh with --force",
                dir.display(),
                layout.manifest
            );
        }
        // A finished job's files must hold what its manifest counts; an unfinished one's
        // data files must all be there once a point is done.
        if old["complete"] == json!(true) {
            check_rows(dir, &layout, &old).context("--resume")?;
        }
        // The finished points: whole index rows, in grid order.
        let index_spec = &layout.files[layout.index_file];
        let index_text = read_resumable(index_spec, &dir.join(index_spec.name))?;
        check_header(index_spec, &index_text, dir)?;
        let (_, lines) = whole_lines(&index_text);
        let mut done = 0;
        for (line, _) in &lines {
            let key = line_key(line, layout.key_fields);
            match keys.get(done) {
                Some(k) if k == key => done += 1,
                _ => bail!(
                    "--resume: {} in {} does not belong to this job at row {} (key {key})",
                    index_spec.name,
                    dir.display(),
                    done + 2
                ),
            }
        }
        if done > 0
            && let Some(spec) = layout.files.iter().find(|spec| !dir.join(spec.name).exists())
        {
            bail!(
                "--resume: {} lacks {}, which holds rows of the {done} points finished: \
                 run the job again (without --resume)",
                dir.display(),
                spec.name
            );
        }
        let done = done.min(keep_at_most);
        let finished: HashSet<&str> = keys[..done].iter().map(String::as_str).collect();
        let mut files = Vec::new();
        for spec in &layout.files {
            let path = dir.join(spec.name);
            let text = read_resumable(spec, &path)?;
            check_header(spec, &text, dir)?;
            let (header_end, lines) = whole_lines(&text);
            let mut keep = header_end;
            let mut rows = 0u64;
            for (line, end) in lines {
                if !finished.contains(line_key(line, layout.key_fields)) {
                    break;
                }
                keep = end;
                rows += 1;
            }
            if keep < text.len() {
                let f = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&path)
                    .with_context(|| format!("cannot open {}", path.display()))?;
                f.set_len(keep as u64)
                    .with_context(|| format!("cannot truncate {}", path.display()))?;
            }
            files.push(CsvFile::append(&path, rows)?);
        }
        let mut out = GridOutput {
            dir: dir.to_path_buf(),
            layout,
            settings,
            files,
            pending: Vec::new(),
        };
        out.write_manifest(false, done)?;
        Ok((out, done))
    }

    /// Writes a row of file number `i` of the layout; rows of the index file wait for
    /// [`commit`](Self::commit).
    pub fn row(&mut self, i: usize, fields: Vec<String>) -> Result<()> {
        if i == self.layout.index_file {
            self.pending.push(fields);
            Ok(())
        } else {
            self.files[i].row(fields)
        }
    }

    /// Puts the points written so far on disk: flushes every other file, then writes and
    /// flushes the held-back index rows.
    pub fn commit(&mut self) -> Result<()> {
        let index = self.layout.index_file;
        for (i, f) in self.files.iter_mut().enumerate() {
            if i != index {
                f.flush()?;
            }
        }
        for fields in self.pending.drain(..) {
            self.files[index].row(fields)?;
        }
        self.files[index].flush()
    }

    fn flush(&mut self) -> Result<()> {
        self.files.iter_mut().try_for_each(CsvFile::flush)
    }

    /// Flushes and rewrites the manifest: complete (with the row counts of every file), or
    /// incomplete with `done` points finished. The continuation checkpoint goes once complete.
    pub fn finish(mut self, complete: bool, done: usize) -> Result<()> {
        self.commit()?;
        self.write_manifest(complete, done)?;
        if complete {
            let _ = std::fs::remove_file(self.dir.join(CHECKPOINT));
        }
        Ok(())
    }

    /// Saves `state` (JSON) as the continuation checkpoint after `done` points, once their
    /// rows are on disk.
    pub fn checkpoint(&mut self, done: usize, state: Value) -> Result<()> {
        self.commit()?;
        write_json(&self.dir.join(CHECKPOINT), &json!({"done": done, "state": state}))
    }

    fn write_manifest(&mut self, complete: bool, done: usize) -> Result<()> {
        let mut m = self.settings.clone();
        let o = m
            .as_object_mut()
            .ok_or_else(|| anyhow!("the settings of a grid job must be a JSON object"))?;
        o.insert("complete".into(), json!(complete));
        if complete {
            let rows: serde_json::Map<String, Value> = self
                .layout
                .files
                .iter()
                .zip(&self.files)
                .map(|(s, f)| (s.name.to_string(), json!(f.rows())))
                .collect();
            o.insert("rows".into(), Value::Object(rows));
        } else {
            o.insert("done".into(), json!(done));
        }
        write_json(&self.dir.join(self.layout.manifest), &m)
    }
}

/// File name of a continuation's checkpoint (the state to start the next point from).
pub const CHECKPOINT: &str = "checkpoint.json";

/// Reads the continuation checkpoint of `dir`: the number of points it covers and the state.
pub fn read_checkpoint(dir: &Path) -> Result<Option<(usize, Value)>> {
    let path = dir.join(CHECKPOINT);
    if !path.exists() {
        return Ok(None);
    }
    let c = read_json(&path)?;
    let done = c["done"]
        .as_u64()
        .ok_or_else(|| anyhow!("{} lacks `done`", path.display()))? as usize;
    Ok(Some((done, c["state"].clone())))
}

fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// The text of a job's file to resume; a file cut within its header (killed before the
/// first flush) is rewritten with its header alone.
fn read_resumable(spec: &CsvSpec, path: &Path) -> Result<String> {
    let text = if path.exists() {
        read_text(path)?
    } else {
        String::new()
    };
    let header = spec.columns.join(",") + "\n";
    if text.len() < header.len() && header.starts_with(&text) {
        write_atomic(path, header.as_bytes())?;
        return Ok(header);
    }
    Ok(text)
}

/// Checks that every file of the finished job in `dir` holds, whole, the rows its manifest
/// `m` counts: an error naming the file if one was deleted, cut or changed since.
fn check_rows(dir: &Path, layout: &Layout, m: &Value) -> Result<()> {
    for spec in &layout.files {
        let expected = m["rows"][spec.name].as_u64().ok_or_else(|| {
            anyhow!(
                "{}: {} does not count the rows of {}",
                dir.display(),
                layout.manifest,
                spec.name
            )
        })?;
        let text = read_text(&dir.join(spec.name))?;
        check_header(spec, &text, dir)?;
        let (_, lines) = whole_lines(&text);
        let whole = text.ends_with('\n');
        if lines.len() as u64 != expected || !whole {
            bail!(
                "{}: {} holds {} rows, its {} says {expected}: the job's files were changed or cut \
                 since it finished; run it again (without --resume)",
                dir.display(),
                spec.name,
                lines.len(),
                layout.manifest
            );
        }
    }
    Ok(())
}

fn check_header(spec: &CsvSpec, text: &str, dir: &Path) -> Result<()> {
    let header = text.lines().next().unwrap_or("");
    if header != spec.columns.join(",") {
        bail!(
            "{} in {} does not have the columns this job writes",
            spec.name,
            dir.display()
        );
    }
    Ok(())
}

/// Merges the shard directories `shards` of one grid job into `out`. `keys_of` gives the keys
/// of the job's points in grid order from its manifest settings. Refuses incomplete shards,
/// shards of different jobs, missing or repeated shards, files that do not hold the rows
/// their manifest counts, and any grid point missing or present twice. Writes into a
/// temporary directory beside `out`, renamed into place once everything is written.
pub fn merge<F>(shards: &[PathBuf], out: &Path, layout: &Layout, keys_of: F) -> Result<()>
where
    F: Fn(&Value) -> Result<Vec<String>>,
{
    let mut settings: Option<Value> = None;
    let mut seen = Vec::new();
    for dir in shards {
        let m = read_json(&dir.join(layout.manifest))?;
        let shard = &m["shard"];
        if shard.is_null() {
            bail!("{} is not a shard (it was run without --shard)", dir.display());
        }
        if m["complete"] != json!(true) {
            bail!(
                "{} is incomplete ({} of its points done): rerun that shard with --resume before merging",
                dir.display(),
                m["done"]
            );
        }
        let index = shard["index"].as_u64();
        let count = shard["count"].as_u64();
        let (Some(index), Some(count)) = (index, count) else {
            bail!("{}: bad `shard` in {}", dir.display(), layout.manifest);
        };
        seen.push((index, count, dir));
        check_rows(dir, layout, &m)?;
        let s = settings_of(&m);
        match &settings {
            None => settings = Some(s),
            Some(first) if *first != s => bail!("{} is a shard of a different job", dir.display()),
            Some(_) => {}
        }
    }
    let settings = settings.ok_or_else(|| anyhow!("no shards given"))?;
    let count = seen[0].1;
    let mut indices: Vec<u64> = seen.iter().map(|s| s.0).collect();
    indices.sort_unstable();
    indices.dedup();
    if seen.iter().any(|s| s.1 != count) || indices.len() != seen.len() || indices.len() as u64 != count {
        let given: Vec<String> = seen.iter().map(|s| format!("{}/{}", s.0, s.1)).collect();
        let missing: Vec<u64> = (0..count).filter(|i| !indices.contains(i)).collect();
        let twice: Vec<u64> = indices
            .iter()
            .copied()
            .filter(|i| seen.iter().filter(|s| s.0 == *i).count() > 1)
            .collect();
        bail!(
            "need each of the {count} shards exactly once; given {} (missing {missing:?}, given twice {twice:?})",
            given.join(", ")
        );
    }
    let keys = keys_of(&settings)?;
    let tmp = out.with_file_name(format!(
        ".{}.merging-{}",
        out.file_name()
            .map_or("merged".into(), |n| n.to_string_lossy().into_owned()),
        std::process::id()
    ));
    let result = write_merged(shards, &tmp, layout, &keys, &settings);
    if let Err(e) = result {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    if out.exists() {
        let empty = std::fs::read_dir(out)
            .map(|mut d| d.next().is_none())
            .unwrap_or(false);
        if !empty {
            let _ = std::fs::remove_dir_all(&tmp);
            bail!(
                "{} exists and is not empty: merge into a new directory",
                out.display()
            );
        }
        std::fs::remove_dir(out).with_context(|| format!("cannot replace {}", out.display()))?;
    }
    std::fs::rename(&tmp, out).with_context(|| format!("cannot move the merged files to {}", out.display()))
}

fn write_merged(
    shards: &[PathBuf],
    tmp: &Path,
    layout: &Layout,
    keys: &[String],
    settings: &Value,
) -> Result<()> {
    create_dir(tmp)?;
    let mut rows_count = serde_json::Map::new();
    for (f, spec) in layout.files.iter().enumerate() {
        let mut groups: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for dir in shards {
            let text = read_text(&dir.join(spec.name))?;
            let (_, lines) = whole_lines(&text);
            let mut mine: BTreeMap<String, Vec<String>> = BTreeMap::new();
            for (line, _) in lines {
                mine.entry(line_key(line, layout.key_fields).to_string())
                    .or_default()
                    .push(line.to_string());
            }
            for (k, rows) in mine {
                if groups.insert(k.clone(), rows).is_some() {
                    bail!("{}: the point {k} appears in two shards", spec.name);
                }
            }
        }
        if f == layout.index_file {
            for k in keys {
                match groups.get(k).map(Vec::len) {
                    Some(1) => {}
                    Some(n) => bail!("{}: the point {k} has {n} rows", spec.name),
                    None => bail!("{}: the point {k} is missing from every shard", spec.name),
                }
            }
        }
        let mut text = spec.columns.join(",");
        text.push('\n');
        let mut n = 0u64;
        for k in keys {
            for r in groups.remove(k).unwrap_or_default() {
                text.push_str(&r);
                text.push('\n');
                n += 1;
            }
        }
        if let Some(k) = groups.keys().next() {
            bail!(
                "{}: rows for {k}, which is not a point of the job's grid",
                spec.name
            );
        }
        write_atomic(&tmp.join(spec.name), text.as_bytes())?;
        rows_count.insert(spec.name.to_string(), json!(n));
    }
    let mut m = settings.clone();
    if let Some(o) = m.as_object_mut() {
        o.insert("complete".into(), json!(true));
        o.insert("rows".into(), Value::Object(rows_count));
    }
    write_json(&tmp.join(layout.manifest), &m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_and_lines() {
        assert_eq!(line_key("0.5,1,2", 1), "0.5");
        assert_eq!(line_key("0.5,1,2", 2), "0.5,1");
        assert_eq!(line_key("0.5", 2), "0.5");
        let (h, lines) = whole_lines("a,b\n1,2\n3,4\n5,");
        assert_eq!(h, 4);
        assert_eq!(lines, vec![("1,2", 8), ("3,4", 12)]);
    }
}
