//! The command line's options as the Python package takes them: parsed by the command line's
//! own definitions (clap), and listed (name, value, default, help, choices) so the package can
//! check keyword arguments, and its stub can declare them.

use clap::{CommandFactory, Parser};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use twister_cli::args::RenderArgs;
use twister_cli::bench::SpeedArgs;
use twister_cli::measure::ErrorArgs;

use crate::{python_spelling, TwisterError};

#[derive(Parser)]
#[command(name = "render", no_binary_name = true)]
pub struct RenderCmd {
    #[command(flatten)]
    pub args: RenderArgs,
}

#[derive(Parser)]
#[command(name = "error", no_binary_name = true)]
pub struct ErrorCmd {
    #[command(flatten)]
    pub args: ErrorArgs,
}

#[derive(Parser)]
#[command(name = "bench_speed", no_binary_name = true)]
pub struct SpeedCmd {
    #[command(flatten)]
    pub args: SpeedArgs,
}

/// Parses options (`["builtin:demo", "--eye-radius", "0.032"]`) into a command's arguments; a
/// bad one raises `TwisterError` naming the parameter as Python spells it.
pub fn parse<C: Parser>(argv: &[String]) -> PyResult<C> {
    C::try_parse_from(argv).map_err(|e| TwisterError::new_err(clap_message(&e)))
}

/// clap's error as one line that starts with the parameter's name: what was wrong with the
/// value and, where the values are few, which it takes.
fn clap_message(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue};
    let context = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => Some(v.join(", ")),
        _ => None,
    };
    let name = context(ContextKind::InvalidArg).and_then(|a| a.split_whitespace().next().map(python_spelling));
    let (Some(name), Some(value)) = (name, context(ContextKind::InvalidValue)) else {
        let text = e.render().to_string();
        return python_spelling(text.lines().next().unwrap_or("bad settings").trim_start_matches("error: "));
    };
    let why = match (std::error::Error::source(e), context(ContextKind::ValidValue)) {
        (_, Some(valid)) => format!("takes one of {valid}"),
        (Some(source), None) => python_spelling(&source.to_string()),
        (None, None) => "not a valid value".to_string(),
    };
    format!("{name}: {value:?}: {why}")
}

/// The options of `command` ("render", "error" or "bench_speed"), each a dict: `name` (Python's
/// spelling), `flag` (the command line's), `takes_value`, `multiple` (comma-separated),
/// `default` (text, or None), `help` (one line), `choices` (the values it takes, or []).
#[pyfunction]
pub fn options<'py>(py: Python<'py>, command: &str) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let cmd = match command {
        "render" => RenderCmd::command(),
        "error" => ErrorCmd::command(),
        "bench_speed" => SpeedCmd::command(),
        other => return Err(TwisterError::new_err(format!("command: {other:?} is not render, error or bench_speed"))),
    };
    let mut out = Vec::new();
    for arg in cmd.get_arguments() {
        let Some(long) = arg.get_long() else { continue };
        if matches!(long, "help" | "version") {
            continue;
        }
        let d = PyDict::new(py);
        d.set_item("name", long.replace('-', "_"))?;
        d.set_item("flag", format!("--{long}"))?;
        d.set_item("takes_value", arg.get_action().takes_values())?;
        d.set_item("multiple", arg.get_value_delimiter().is_some())?;
        let default: Vec<String> = arg.get_default_values().iter().map(|v| v.to_string_lossy().into_owned()).collect();
        d.set_item("default", (!default.is_empty()).then(|| default.join(",")))?;
        let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
        d.set_item("help", python_spelling(help.lines().next().unwrap_or("")))?;
        let choices: Vec<String> =
            arg.get_possible_values().iter().filter(|v| !v.is_hide_set()).map(|v| v.get_name().to_string()).collect();
        d.set_item("choices", if arg.get_action().takes_values() { choices } else { Vec::new() })?;
        d.set_item("type", value_type(arg))?;
        out.push(d);
    }
    Ok(out)
}

/// What a value is, for the stub's types: "bool" (a switch), "int", "float", "path", "choice"
/// (one of `choices`) or "text" (anything else: a list, a point "X,Y,Z", a method "fixed:8").
fn value_type(arg: &clap::Arg) -> &'static str {
    use std::any::TypeId;
    if !arg.get_action().takes_values() {
        return "bool";
    }
    if !arg.get_possible_values().is_empty() {
        return "choice";
    }
    let id = arg.get_value_parser().type_id();
    if [TypeId::of::<u8>(), TypeId::of::<u32>(), TypeId::of::<u64>(), TypeId::of::<usize>()].iter().any(|t| id == *t) {
        "int"
    } else if id == TypeId::of::<f32>() || id == TypeId::of::<f64>() {
        "float"
    } else if id == TypeId::of::<std::path::PathBuf>() {
        "path"
    } else {
        "text"
    }
}
