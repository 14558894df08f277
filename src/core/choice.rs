//! Settings that take one of a few named values (`panorama = "equirect"`, `tonemap =
//! "aces"`): each such type lists its values with the name a user writes and one line of help.
//! Callers build their own front ends on it — the command line's possible values, the Python
//! package's keyword arguments — so the library depends on neither.

use crate::error::{Error, Result};

/// A setting with a fixed set of named values.
pub trait Choice: Copy + PartialEq + Sized + Send + Sync + 'static {
    /// Every value a user may name, in the order help lists them.
    const CHOICES: &'static [Self];
    /// The name a user writes (kebab-case, as the command line and the JSON files spell it).
    fn name(self) -> &'static str;
    /// One line saying what the value does, for help texts.
    fn help(self) -> &'static str;

    /// The value named `name` (kebab-case; snake_case is taken too, as Python spells names).
    fn from_name(name: &str) -> Option<Self> {
        let name = name.trim().replace('_', "-");
        Self::CHOICES.iter().copied().find(|c| c.name().eq_ignore_ascii_case(&name))
    }

    /// [`Choice::from_name`], or an error naming `setting` and the values it takes.
    fn parse_for(setting: &'static str, name: &str) -> Result<Self> {
        Self::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = Self::CHOICES.iter().map(|c| c.name()).collect();
            Error::setting(setting, format!("{name:?} is not one of {}", names.join(", ")))
        })
    }
}

/// Implements [`Choice`] for an enum: `choices!(Type { Variant => ("name", "help"), … })`,
/// listing exactly the values a user may name.
#[macro_export]
macro_rules! choices {
    ($ty:ident { $($variant:ident => ($name:literal, $help:literal)),+ $(,)? }) => {
        impl $crate::core::choice::Choice for $ty {
            const CHOICES: &'static [Self] = &[$($ty::$variant),+];
            fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name,)+
                    #[allow(unreachable_patterns)]
                    _ => "",
                }
            }
            fn help(self) -> &'static str {
                match self {
                    $($ty::$variant => $help,)+
                    #[allow(unreachable_patterns)]
                    _ => "",
                }
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::panoramas::panorama::PanoramaKind;
    use crate::core::shading::light::Tonemap;

    /// Every value of `C` comes back from its name, in kebab and snake case, and the JSON files
    /// spell it so; each has a line of help.
    fn round_trips<C: Choice + serde::Serialize + std::fmt::Debug>() {
        for &value in C::CHOICES {
            assert_eq!(C::from_name(value.name()), Some(value));
            assert_eq!(C::from_name(&value.name().replace('-', "_")), Some(value));
            assert_eq!(serde_json::to_value(value).unwrap(), value.name(), "the JSON files spell it so");
            assert!(!value.help().is_empty());
        }
    }

    #[test]
    fn names_round_trip_in_kebab_and_snake_case_and_match_the_json_spelling() {
        round_trips::<PanoramaKind>();
        round_trips::<Tonemap>();
        assert_eq!(Tonemap::from_name("pbr_neutral"), Some(Tonemap::PbrNeutral));
        // The linear tone map belongs to HDR frames and is no user's choice.
        assert_eq!(Tonemap::from_name("linear"), None);
        assert!(!Tonemap::CHOICES.contains(&Tonemap::Linear));
    }

    #[test]
    fn an_unknown_name_is_an_error_naming_the_setting_and_the_values() {
        let parsed: Result<PanoramaKind> = Choice::parse_for("view.projection.panorama", "dome");
        let e = parsed.unwrap_err().to_string();
        assert_eq!(
            e,
            "view.projection.panorama: \"dome\" is not one of cylinder, equirect, vr180, fisheye, cubemap, cave"
        );
    }
}
