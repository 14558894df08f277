//! Values over time read from a CSV file (issue 18): `--gaze-path` (yaw, pitch) and
//! `--viewer-path` (x, y, z and an optional yaw) — rows of a time in seconds and numbers, times
//! increasing; between rows the numbers are blended linearly, before the first and after the
//! last they hold.

use std::path::Path;

use crate::error::{Error, Result};

/// Rows of (time, values).
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    pub rows: Vec<(f32, Vec<f32>)>,
}

impl Timeline {
    /// Reads `path` for `setting` (named in errors): rows of a time and `min..=max` further
    /// numbers (all rows as many), `#` comments, a header row of names skipped; `check` says
    /// what is wrong with a row's numbers, if anything. One line naming the file and the row
    /// otherwise.
    pub fn read(
        path: &Path,
        setting: &'static str,
        (min, max): (usize, usize),
        what: &str,
        check: impl Fn(&[f32]) -> Option<String>,
    ) -> Result<Timeline> {
        let bad = |m: String| Error::setting(setting, format!("{}: {m}", path.display()));
        let size = std::fs::metadata(path).map_err(|e| bad(e.to_string()))?.len();
        if size > 64 << 20 {
            return Err(bad("larger than 64 MiB".into()));
        }
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_path(path)
            .map_err(|e| bad(e.to_string()))?;
        let mut rows: Vec<(f32, Vec<f32>)> = Vec::new();
        for (k, record) in reader.records().enumerate() {
            let record = record.map_err(|e| bad(format!("row {}: {e}", k + 1)))?;
            let numbers: Vec<Option<f32>> = record.iter().map(|f| f.parse::<f32>().ok()).collect();
            if k == 0 && numbers.iter().all(Option::is_none) {
                continue; // a header
            }
            let values: Option<Vec<f32>> = numbers.into_iter().collect();
            let fail = |why: String| bad(format!("row {}: expected {what}: {why}", k + 1));
            let Some(values) = values.filter(|v| v.iter().all(|x| x.is_finite())) else {
                return Err(fail("finite numbers".into()));
            };
            let (t, rest) = values.split_first().ok_or_else(|| fail("a time first".into()))?;
            if rest.len() < min || rest.len() > max || rows.first().is_some_and(|r| r.1.len() != rest.len()) {
                return Err(fail("the same count of numbers in every row".into()));
            }
            if rows.last().is_some_and(|r| *t <= r.0) {
                return Err(fail("times increasing".into()));
            }
            if let Some(why) = check(rest) {
                return Err(fail(why));
            }
            rows.push((*t, rest.to_vec()));
        }
        if rows.is_empty() {
            return Err(bad("no rows".into()));
        }
        Ok(Timeline { rows })
    }

    /// The values at time t.
    pub fn at(&self, t: f32) -> Vec<f32> {
        let r = &self.rows;
        let i = r.partition_point(|row| row.0 <= t);
        if i == 0 {
            return r[0].1.clone();
        }
        if i == r.len() {
            return r[i - 1].1.clone();
        }
        let (a, b) = (&r[i - 1], &r[i]);
        let s = (t - a.0) / (b.0 - a.0);
        a.1.iter().zip(&b.1).map(|(x, y)| x + (y - x) * s).collect()
    }
}
