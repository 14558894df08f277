//! `twister._twister`: the extension module under the Python package `twister`
//! (python/twister/). The package turns keyword arguments into the command line's options
//! (`eye_radius=0.032` → `--eye-radius 0.032`); this module parses them with the command line's
//! own definitions (`twister_cli::args`) and runs the command line's own steps on a renderer kept
//! open, so a keyword means exactly what its option means and draws the same pixels.
//!
//! Errors: bad settings raise `TwisterError` (a `ValueError`), files that cannot be read or
//! written `TwisterFileError` (an `OSError`), a missing or failing device `TwisterDeviceError`
//! (a `RuntimeError`); each message one line naming the parameter as Python spells it. A panic
//! is caught and raised as `TwisterDeviceError`; none crosses into Python.

use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

mod frame;
mod options;
mod renderer;

create_exception!(twister, TwisterError, PyValueError, "A bad setting: the message names the parameter.");
create_exception!(twister, TwisterFileError, PyOSError, "A scene, path or output file that cannot be read or written.");
create_exception!(twister, TwisterDeviceError, PyRuntimeError, "No usable GPU adapter, or the device failed.");

/// The command line's spelling of options in a message, as Python spells parameters:
/// `--eye-radius` → `eye_radius`.
pub fn python_spelling(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find("--") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 2..];
        let name_len = after.find(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).unwrap_or(after.len());
        let name = &after[..name_len];
        if name.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.push_str(&name.trim_end_matches('-').replace('-', "_"));
        } else {
            out.push_str("--");
            out.push_str(name);
        }
        rest = &after[name_len..];
    }
    out.push_str(rest);
    out
}

/// A library error as the Python exception of its kind, in Python's spelling.
pub fn to_py(error: twister::Error) -> PyErr {
    use twister::Error;
    // A setting the command line takes from the environment (the adapter) keeps its own name.
    let error = match error {
        Error::Setting { setting, message }
            if !twister_cli::flags::flag_of(setting).is_some_and(|f| f.starts_with("--")) =>
        {
            let name = setting.rsplit('.').next().unwrap_or(setting);
            return TwisterError::new_err(format!("{name}: {}", python_spelling(&message)));
        }
        other => twister_cli::flags::for_user(other),
    };
    let text = python_spelling(&error.to_string());
    match error {
        Error::Scene { .. } | Error::Output { .. } => TwisterFileError::new_err(text),
        Error::NoGpu(_) | Error::Gpu(_) => TwisterDeviceError::new_err(text),
        _ => TwisterError::new_err(text),
    }
}

/// Runs `work` without the GIL (other Python threads run meanwhile), a panic caught and raised
/// as `TwisterDeviceError`, a library error as [`to_py`]'s exception.
pub fn without_gil<T: Send>(py: Python<'_>, work: impl FnOnce() -> twister::Result<T> + Send) -> PyResult<T> {
    let result = py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)));
    match result {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(error)) => Err(to_py(error)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("a panic");
            Err(TwisterDeviceError::new_err(format!("internal error, please report it: {what}")))
        }
    }
}

#[pymodule]
fn _twister(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("TwisterError", py.get_type::<TwisterError>())?;
    m.add("TwisterFileError", py.get_type::<TwisterFileError>())?;
    m.add("TwisterDeviceError", py.get_type::<TwisterDeviceError>())?;
    m.add_class::<renderer::Renderer>()?;
    m.add_class::<renderer::Scene>()?;
    m.add_class::<frame::Frame>()?;
    m.add_function(wrap_pyfunction!(options::options, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn options_in_messages_take_pythons_spelling() {
        assert_eq!(super::python_spelling("--eye-radius: must be ≥ 0"), "eye_radius: must be ≥ 0");
        assert_eq!(super::python_spelling("--width/--height: too big"), "width/height: too big");
        assert_eq!(super::python_spelling("needs --panorama fisheye -- or not"), "needs panorama fisheye -- or not");
    }
}
