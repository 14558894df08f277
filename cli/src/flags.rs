//! The command line's names for the library's settings: the library's errors name the field
//! they are about (`Error::Setting`, e.g. `subdivision.edge_px`), and the command line tells its
//! user which option sets that field (`--edge-px`).

use twister::Error;

/// Each setting the library names in its errors, and the option that sets it.
pub const FLAGS: &[(&str, &str)] = &[
    ("adapter", "TWISTER_ADAPTER"),
    ("view.projection.screen_radius", "--screen-radius"),
    ("view.projection.eye_radius", "--eye-radius"),
    ("view.projection.convergence", "--convergence"),
    ("view.projection.pole_merge", "--pole-merge"),
    ("view.projection.fov", "--fov"),
    ("view.projection.head", "--head"),
    ("view.projection.dome_tilt", "--dome-tilt"),
    ("view.projection.width/height", "--width/--height"),
    ("view.projection.vertical", "--vertical"),
    ("view.viewer", "--viewer"),
    ("view.yaw_deg", "--yaw"),
    ("subdivision.method", "--method"),
    ("subdivision.edge_px", "--edge-px"),
    ("subdivision.max_error_px", "--max-error-px"),
    ("subdivision.max_div", "--max-div"),
    ("subdivision.memory_mb", "--memory-mb"),
    ("shading.exposure_ev", "--exposure"),
    ("shading.environment_yaw_deg", "--environment-yaw"),
    ("shading.reflect_max", "--reflect-max"),
    ("shading.light", "--light"),
    ("shading.shadow_map_size", "--shadow-map-size"),
    ("shading.hdr", "--hdr"),
    ("shading.samples", "--samples"),
    ("shading.anisotropy", "--anisotropy"),
    ("lod.p2/p3", "--lod-p2/--lod-p3"),
    ("lod.d_inf", "--lod-dinf"),
    ("environment", "--environment"),
    ("fit", "--fit"),
    ("gaze_path", "--gaze-path"),
    ("viewer_path", "--viewer-path"),
    ("head_path", "--head-path"),
    ("cave", "--cave"),
    ("view.projection.wall", "--cave"),
    ("view.projection.tile", "--max-tile"),
];

/// Inputs only the library's own callers hand it, which the command line never builds (a
/// frame's recording, `Renderer::render_recorded`): their errors keep the library's name.
pub const LIBRARY_ONLY: &[&str] = &["recording"];

/// The option that sets `setting`, if the command line has one.
pub fn flag_of(setting: &str) -> Option<&'static str> {
    FLAGS.iter().find(|(s, _)| *s == setting).map(|(_, flag)| *flag)
}

/// An error as the command line's user should read it: a setting named by its option.
pub fn for_user(error: Error) -> Error {
    match error {
        Error::Setting { setting, message } => match flag_of(setting) {
            Some(option) => Error::Option { option, message },
            None => Error::Setting { setting, message },
        },
        other => other,
    }
}

/// A CAVE wall's error with the wall named.
pub fn name_wall(error: Error, wall: &str) -> Error {
    match error {
        Error::Setting { setting: "view.projection.wall", message } => {
            Error::Setting { setting: "view.projection.wall", message: format!("wall {wall:?}: {message}") }
        }
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library's source files (the workspace root's src/), with their text.
    fn library_sources() -> Vec<(String, String)> {
        let mut files = Vec::new();
        let mut stack = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src")];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    files.push((path.display().to_string(), std::fs::read_to_string(&path).unwrap()));
                }
            }
        }
        files
    }

    #[test]
    fn the_library_names_no_command_line_flag() {
        // Outside comments, no line of the library holds `--` followed by a letter: its errors,
        // warnings and messages name settings, and only the command line names its flags.
        let mut found = Vec::new();
        for (file, text) in library_sources() {
            for (k, line) in text.lines().enumerate() {
                let code = line.trim_start();
                let flag =
                    code.match_indices("--").any(|(i, _)| code[i + 2..].starts_with(|c: char| c.is_ascii_lowercase()));
                if flag && !code.starts_with("//") {
                    found.push(format!("{file}:{}: {code}", k + 1));
                }
            }
        }
        assert!(found.is_empty(), "the library names command-line flags:\n{}", found.join("\n"));
    }

    #[test]
    fn every_setting_the_library_names_has_an_option() {
        // The library's sources, scanned for `Error::setting("NAME"` (a new setting without an
        // option here would reach the user by its field name).
        let mut named = Vec::new();
        for (file, text) in library_sources() {
            for (i, _) in text.match_indices("Error::setting(") {
                let rest = text[i + 15..].trim_start();
                if let Some(name) = rest.strip_prefix('"').and_then(|r| r.split('"').next()) {
                    named.push((name.to_string(), file.clone()));
                }
            }
        }
        assert!(named.len() >= 20, "found only {named:?}");
        for (name, file) in &named {
            let known = flag_of(name).is_some() || LIBRARY_ONLY.contains(&name.as_str());
            assert!(known, "{file}: setting {name} has no option in cli/src/flags.rs");
        }
        assert!(LIBRARY_ONLY.iter().all(|n| flag_of(n).is_none()), "a library-only input has an option");
        let error = for_user(Error::setting("subdivision.edge_px", "must be ≥ 0.25"));
        assert_eq!(error.to_string(), "--edge-px: must be ≥ 0.25");
    }
}
