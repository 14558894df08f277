//! `bench startup`: the whole-process time of `twister render` commands, each in a fresh
//! process (a still from the command line pays for opening the device and building its
//! pipelines every time): **cold** (Mesa's shader cache and twister's pipeline cache emptied:
//! a fresh `XDG_CACHE_HOME`), **warm** (the same caches after one run) and **warm without the
//! pipeline cache** (`TWISTER_CACHE_DIR=off`, Mesa's cache warm), the median of `reps` runs each.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use twister::error::{Error, Result};

use super::speed::median;

/// The renders timed unless others are given: the default one, and a tiny one (what is left is
/// the process's fixed cost).
pub const DEFAULT_CASES: [&str; 2] = ["render", "render builtin:triangle@3 --width 64 --height 16"];

#[derive(Clone, Debug, serde::Serialize)]
pub struct StartupRow {
    /// The command's arguments after `twister`.
    pub command: String,
    /// `cold`, `warm` or `warm, no pipeline cache`.
    pub caches: String,
    pub ms_median: f64,
    pub ms_min: f64,
    pub runs: usize,
}

/// One run of `args` (output into `out`) with the caches under `cache_home`; wall milliseconds.
fn run_once(args: &[String], out: &Path, cache_home: &Path, pipeline_cache: bool) -> Result<f64> {
    let exe = std::env::current_exe().map_err(|e| Error::option("--case", format!("the twister executable: {e}")))?;
    let mut command = Command::new(exe);
    command
        .args(args)
        .arg("--out")
        .arg(out)
        .env("XDG_CACHE_HOME", cache_home)
        .env("MESA_SHADER_CACHE_DIR", cache_home.join("mesa"));
    if pipeline_cache {
        command.env_remove("TWISTER_CACHE_DIR");
    } else {
        command.env("TWISTER_CACHE_DIR", "off");
    }
    let start = Instant::now();
    let output = command.output().map_err(|e| Error::option("--case", format!("twister {}: {e}", args.join(" "))))?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let why = stderr.lines().find(|l| l.starts_with("error")).unwrap_or("no message").trim_start_matches("error: ");
        return Err(Error::option("--case", format!("`twister {}` failed: {why}", args.join(" "))));
    }
    Ok(ms)
}

/// Times every case cold, warm, and warm without the pipeline cache, in a scratch folder.
pub fn startup(cases: &[String], reps: usize, scratch: &Path, progress: impl Fn(&str)) -> Result<Vec<StartupRow>> {
    let mut rows = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let args: Vec<String> = case.split_whitespace().map(str::to_string).collect();
        let out = scratch.join(format!("out-{k}"));
        let fresh = |name: String| -> Result<PathBuf> {
            let dir = scratch.join(name);
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
            Ok(dir)
        };
        progress(&format!("{case}: cold"));
        let cold: Vec<f64> =
            (0..reps).map(|r| run_once(&args, &out, &fresh(format!("cold-{k}-{r}"))?, true)).collect::<Result<_>>()?;
        let warm_home = fresh(format!("warm-{k}"))?;
        run_once(&args, &out, &warm_home, true)?;
        progress(&format!("{case}: warm"));
        let warm: Vec<f64> = (0..reps).map(|_| run_once(&args, &out, &warm_home, true)).collect::<Result<_>>()?;
        progress(&format!("{case}: warm, no pipeline cache"));
        let plain: Vec<f64> = (0..reps).map(|_| run_once(&args, &out, &warm_home, false)).collect::<Result<_>>()?;
        for (caches, times) in [("cold", cold), ("warm", warm), ("warm, no pipeline cache", plain)] {
            let ms_min = times.iter().copied().fold(f64::INFINITY, f64::min);
            rows.push(StartupRow {
                command: case.clone(),
                caches: caches.to_string(),
                ms_median: median(times.clone()),
                ms_min,
                runs: times.len(),
            });
        }
    }
    Ok(rows)
}

/// The rows as a text table.
pub fn startup_table(rows: &[StartupRow]) -> String {
    let mut out = format!("{:<56} {:<24} {:>10} {:>10}\n", "command", "caches", "median ms", "min ms");
    for r in rows {
        out += &format!(
            "{:<56} {:<24} {:>10.0} {:>10.0}\n",
            format!("twister {}", r.command),
            r.caches,
            r.ms_median,
            r.ms_min
        );
    }
    out
}
