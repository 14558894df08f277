//! `--head-input FILE|-`: a tracker's lines, `time,x,y,z,yaw,pitch`, read on a thread of their
//! own as they arrive and applied by the window when its clock reaches their time. A line
//! that is not six finite numbers (or longer than `MAX_LINE` bytes, or out of time order) stops
//! the window with one line naming the input and the line.

use std::io::{BufRead, Read};
use std::path::Path;
use std::sync::mpsc::{sync_channel, Receiver, TryRecvError};

use glam::Vec3;
use twister::error::{Error, Result};

/// The longest line read (a file that never ends a line is refused, not read without bound).
pub const MAX_LINE: u64 = 4096;

/// Lines read ahead of the window's clock (the reader waits beyond them: bounded memory).
const READ_AHEAD: usize = 1024;

/// One line: the head (or viewer) place in scene units, its yaw and the gaze's pitch, degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadSample {
    pub time: f64,
    pub position: Vec3,
    pub yaw: f32,
    pub pitch: f32,
}

/// Parses one line (`name` and `line` for the message).
pub fn parse_line(text: &str, name: &str, line: usize) -> Result<HeadSample> {
    let bad = |why: String| Error::option("--head-input", format!("{name} line {line}: {why}"));
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| bad(format!("'{}': {e} (expected time,x,y,z,yaw,pitch)", text.trim())))?;
    let [time, x, y, z, yaw, pitch] = values[..] else {
        return Err(bad(format!("{} values, expected 6: time,x,y,z,yaw,pitch", values.len())));
    };
    if !values.iter().all(|v| v.is_finite() && v.abs() <= 1e9) {
        return Err(bad("a value is not a finite number within ±1e9".into()));
    }
    if time < 0.0 || pitch.abs() > 89.0 {
        return Err(bad("time must be ≥ 0 and pitch within ±89 degrees".into()));
    }
    Ok(HeadSample { time, position: Vec3::new(x as f32, y as f32, z as f32), yaw: yaw as f32, pitch: pitch as f32 })
}

/// The reader's lines (or its error), the one read but not yet due, and whether it ended.
pub struct HeadInput {
    receive: Receiver<Result<HeadSample>>,
    next: Option<HeadSample>,
    ended: bool,
}

impl HeadInput {
    /// Opens `path` (`-`: standard input) and starts its reader.
    pub fn open(path: &Path) -> Result<HeadInput> {
        let name = path.display().to_string();
        let source: Box<dyn Read + Send> = if name == "-" {
            Box::new(std::io::stdin())
        } else {
            let meta = std::fs::metadata(path).map_err(|e| Error::option("--head-input", format!("{name}: {e}")))?;
            if meta.is_dir() {
                return Err(Error::option("--head-input", format!("{name} is a folder")));
            }
            Box::new(std::fs::File::open(path).map_err(|e| Error::option("--head-input", format!("{name}: {e}")))?)
        };
        let (send, receive) = sync_channel(READ_AHEAD);
        std::thread::spawn(move || {
            let mut reader = std::io::BufReader::new(source);
            let mut last = 0.0;
            for line in 1.. {
                let mut buf = Vec::new();
                let read = (&mut reader).take(MAX_LINE + 1).read_until(b'\n', &mut buf);
                let sample = match read {
                    Ok(0) => return,
                    Err(e) => Err(Error::option("--head-input", format!("{name}: {e}"))),
                    Ok(_) if buf.len() as u64 > MAX_LINE => {
                        Err(Error::option("--head-input", format!("{name} line {line}: longer than {MAX_LINE} bytes")))
                    }
                    Ok(_) => match std::str::from_utf8(&buf) {
                        Err(_) => Err(Error::option("--head-input", format!("{name} line {line}: not UTF-8 text"))),
                        Ok(t) if t.trim().is_empty() || t.trim_start().starts_with('#') => continue,
                        Ok(t) => parse_line(t, &name, line).and_then(|s| {
                            if s.time < last {
                                Err(Error::option(
                                    "--head-input",
                                    format!("{name} line {line}: time {} before the line above's {last}", s.time),
                                ))
                            } else {
                                last = s.time;
                                Ok(s)
                            }
                        }),
                    },
                };
                let stop = sample.is_err();
                if send.send(sample).is_err() || stop {
                    return;
                }
            }
        });
        Ok(HeadInput { receive, next: None, ended: false })
    }

    /// The latest line due at `t` seconds (None: none new), or the reader's error.
    pub fn due(&mut self, t: f64) -> Result<Option<HeadSample>> {
        let mut latest = None;
        loop {
            if let Some(s) = self.next.take() {
                if s.time > t {
                    self.next = Some(s);
                    return Ok(latest);
                }
                latest = Some(s);
            }
            if self.ended {
                return Ok(latest);
            }
            match self.receive.try_recv() {
                Ok(sample) => self.next = Some(sample?),
                Err(TryRecvError::Empty) => return Ok(latest),
                Err(TryRecvError::Disconnected) => self.ended = true,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_parse_and_bad_lines_name_the_input_and_line() {
        let s = parse_line("0.5, 1, 2, -3, 45, -10\n", "t.csv", 1).unwrap();
        assert_eq!(s, HeadSample { time: 0.5, position: Vec3::new(1.0, 2.0, -3.0), yaw: 45.0, pitch: -10.0 });
        for (text, why) in [
            ("1,2,3", "3 values"),
            ("0,1,2,3,4,x", "'0,1,2,3,4,x'"),
            ("0,1,2,NaN,4,5", "finite"),
            ("0,1,2,3,4,95", "pitch"),
            ("-1,1,2,3,4,5", "time"),
        ] {
            let e = parse_line(text, "t.csv", 7).unwrap_err().to_string();
            assert!(e.contains("t.csv line 7") && e.contains(why), "{text}: {e}");
        }
    }

    #[test]
    fn samples_come_when_due_and_a_line_without_end_is_refused() {
        let dir = std::env::temp_dir().join(format!("twister-head-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("head.csv");
        std::fs::write(&path, "# t,x,y,z,yaw,pitch\n0,0,0,0,0,0\n1,1,0,0,10,0\n2,2,0,0,20,5\n").unwrap();
        let mut input = HeadInput::open(&path).unwrap();
        let wait = |input: &mut HeadInput, t| {
            for _ in 0..200 {
                if let Some(s) = input.due(t).unwrap() {
                    return Some(s);
                }
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
            None
        };
        assert_eq!(wait(&mut input, 0.5).map(|s| s.time), Some(0.0));
        assert_eq!(wait(&mut input, 2.5).map(|s| s.position.x), Some(2.0), "the latest due line");
        std::fs::write(&path, vec![b'1'; 3 * MAX_LINE as usize]).unwrap();
        let mut input = HeadInput::open(&path).unwrap();
        let e = (0..200)
            .find_map(|_| {
                std::thread::sleep(std::time::Duration::from_millis(5));
                input.due(1e9).err()
            })
            .expect("an error");
        assert!(e.to_string().contains("line 1: longer than"), "{e}");
        assert!(HeadInput::open(&dir.join("missing.csv")).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
