//! The one error type of the library. Every variant reads as one line that names what was
//! wrong — the setting (or, from the command line, the option), the file, or the device — and
//! the problem.

use std::path::PathBuf;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A setting has a value twister cannot use: `setting` names the field of the settings the
    /// library was given (e.g. `view.projection.eye_radius` of `RenderSettings`, `lod.p2`), or the
    /// input it was handed (`environment`, `fit`).
    #[error("{setting}: {message}")]
    Setting { setting: &'static str, message: String },
    /// A command-line option has a value twister cannot use (the command line names its flags;
    /// it turns a [`Error::Setting`] into this, naming the flag that sets the field).
    #[error("{option}: {message}")]
    Option { option: &'static str, message: String },
    /// A scene — a file, a file it names, or a built-in — is unreadable or invalid.
    #[error("{scene}: {message}")]
    Scene { scene: String, message: String },
    /// No usable GPU driver, or the device could not be opened.
    #[error("{0}")]
    NoGpu(String),
    /// The GPU refused the work (a validation or out-of-memory error), or the work does not fit
    /// the device.
    #[error("GPU error: {0}")]
    Gpu(String),
    /// An output could not be written; the previous outputs are left as they were.
    #[error("{}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    /// Two frames cannot be compared.
    #[error("cannot compare: {0}")]
    Compare(String),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub fn setting(setting: &'static str, message: impl Into<String>) -> Error {
        Error::Setting { setting, message: message.into() }
    }

    pub fn option(option: &'static str, message: impl Into<String>) -> Error {
        Error::Option { option, message: message.into() }
    }

    pub fn scene(scene: impl Into<String>, message: impl Into<String>) -> Error {
        Error::Scene { scene: scene.into(), message: message.into() }
    }

    pub fn output(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Error {
        Error::Output { path: path.into(), message: message.to_string() }
    }

    /// The same error with the scene named (for errors found in a scene whose name the finder
    /// did not know, e.g. by `Scene::validate`).
    pub fn in_scene(self, name: &str) -> Error {
        match self {
            Error::Scene { scene, message } if scene.is_empty() => Error::Scene { scene: name.into(), message },
            other => other,
        }
    }
}
