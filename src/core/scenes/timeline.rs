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

/// A CSV file's records, as fields: comma-separated, each trimmed and unquoted; blank lines
/// and lines that start with `#` skipped. A timeline's fields are numbers, so a field never
/// holds a comma, a quote or a line break.
fn records(text: &str) -> impl Iterator<Item = impl Iterator<Item = &str>> {
    text.lines()
        .filter(|line| !line.trim().is_empty() && !line.starts_with('#'))
        .map(|line| line.split(',').map(|field| field.trim().trim_matches('"').trim()))
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
        // Read at most 64 MiB and one byte: an endless file (a pipe, a device) ends there too.
        const LIMIT: u64 = 64 << 20;
        let mut text = String::new();
        std::io::Read::read_to_string(
            &mut std::io::Read::take(std::fs::File::open(path).map_err(|e| bad(e.to_string()))?, LIMIT + 1),
            &mut text,
        )
        .map_err(|e| bad(e.to_string()))?;
        if text.len() as u64 > LIMIT {
            return Err(bad("larger than 64 MiB".into()));
        }
        let mut rows: Vec<(f32, Vec<f32>)> = Vec::new();
        for (k, record) in records(&text).enumerate() {
            let numbers: Vec<Option<f32>> = record.map(|f| f.parse::<f32>().ok()).collect();
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

#[cfg(test)]
mod tests {
    use super::*;

    fn read(name: &str, text: &[u8]) -> Result<Timeline> {
        let path = std::env::temp_dir().join(format!("twister-timeline-{}-{name}.csv", std::process::id()));
        std::fs::write(&path, text).unwrap();
        let read = Timeline::read(&path, "gaze_path", (2, 2), "time,yaw,pitch", |_| None);
        std::fs::remove_file(&path).unwrap();
        read
    }

    #[test]
    fn rows_are_read_past_a_header_comments_blank_lines_spaces_and_quotes() {
        let t = read("good", b"time,yaw,pitch\n# a comment\n\n0, 10, \"5\"\r\n 2 ,30,-5\n").unwrap();
        assert_eq!(t.rows, vec![(0.0, vec![10.0, 5.0]), (2.0, vec![30.0, -5.0])]);
        assert_eq!(t.at(1.0), vec![20.0, 0.0]);
        assert_eq!((t.at(-1.0), t.at(9.0)), (vec![10.0, 5.0], vec![30.0, -5.0]));
    }

    #[test]
    fn bad_rows_and_files_are_one_error_naming_the_setting_the_file_and_the_row() {
        for (name, text, needle) in [
            ("short", &b"0,1\n"[..], "row 1: expected time,yaw,pitch: the same count"),
            ("nan", b"0,1,2\n1,NaN,2\n", "row 2: expected time,yaw,pitch: finite numbers"),
            ("word", b"0,1,2\n1,up,2\n", "row 2: expected time,yaw,pitch: finite numbers"),
            ("order", b"1,1,2\n1,1,2\n", "row 2: expected time,yaw,pitch: times increasing"),
            ("empty", b"# nothing\n", "no rows"),
            ("binary", b"\xff\xfe\x00", "valid UTF-8"),
        ] {
            let e = read(name, text).unwrap_err().to_string();
            assert!(
                e.starts_with("gaze_path: ") && e.contains("twister-timeline") && e.contains(needle),
                "{name}: {e}"
            );
            assert_eq!(e.lines().count(), 1, "{name}: {e}");
        }
        let missing = Timeline::read(Path::new("/nonexistent/gaze.csv"), "gaze_path", (2, 2), "", |_| None);
        assert!(missing.unwrap_err().to_string().contains("/nonexistent/gaze.csv"));
    }

    #[cfg(unix)]
    #[test]
    fn an_endless_file_stops_at_the_size_limit() {
        let e = Timeline::read(Path::new("/dev/zero"), "gaze_path", (2, 2), "", |_| None).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("larger than 64 MiB"), "{e}");
    }
}
