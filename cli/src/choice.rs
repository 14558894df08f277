//! The library's named settings (`twister::core::choice::Choice`) as clap options: the values
//! and their one-line help listed under `--help`, the same spellings the JSON files use.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use twister::core::choice::Choice;

/// The value parser of an option that takes one of `T`'s named values.
pub fn choice<T: Choice + Clone>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(T::CHOICES.iter().map(|c| PossibleValue::new(c.name()).help(c.help())))
        .try_map(|name| T::from_name(&name).ok_or_else(|| format!("{name:?} is not a value")))
}
