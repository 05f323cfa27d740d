//! Build parameters by name: each structure's `*Params` struct lists its knobs in one table of
//! [`ParamSpec`]s (key, meaning, valid range) and reads and writes them as [`ParamValue`]s
//! ([`ParamSet`]). Parsing, range checks and the listing of `arbor info --accels` are written once,
//! here, over those tables; [`super::AccelConfig`] picks the table of its structure.

use std::fmt;

use super::AccelKind;

/// The values a parameter accepts. Bounds are inclusive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamRange {
    /// A whole number from `min` to `max` (no upper bound when `None`).
    Int {
        /// Smallest valid value.
        min: i64,
        /// Largest valid value, if any.
        max: Option<i64>,
    },
    /// A whole number from `min` to `max`, or `auto` (the structure picks one from the input size).
    IntOrAuto {
        /// Smallest valid value.
        min: i64,
        /// Largest valid value.
        max: i64,
    },
    /// A finite number from `min` to `max` (no upper bound when `None`).
    Float {
        /// Smallest valid value.
        min: f64,
        /// Largest valid value, if any.
        max: Option<f64>,
    },
    /// One of these words.
    Choice(&'static [&'static str]),
}

impl ParamRange {
    /// Whether `v` is a value of this range.
    pub fn contains(&self, v: &ParamValue) -> bool {
        match (*self, v) {
            (ParamRange::Int { min, max }, ParamValue::Int(x)) => *x >= min && max.is_none_or(|m| *x <= m),
            (ParamRange::IntOrAuto { .. }, ParamValue::Auto) => true,
            (ParamRange::IntOrAuto { min, max }, ParamValue::Int(x)) => (min..=max).contains(x),
            (ParamRange::Float { min, max }, ParamValue::Float(x)) => {
                x.is_finite() && *x >= min && max.is_none_or(|m| *x <= m)
            }
            (ParamRange::Choice(words), ParamValue::Word(w)) => words.contains(w),
            _ => false,
        }
    }

    /// Reads `text` as a value of this range's type, without checking its bounds; `None` when it is not
    /// one (not a number, or not one of the words).
    fn read(&self, text: &str) -> Option<ParamValue> {
        let text = text.trim();
        match *self {
            ParamRange::Int { .. } => text.parse().ok().map(ParamValue::Int),
            ParamRange::IntOrAuto { .. } if text == "auto" => Some(ParamValue::Auto),
            ParamRange::IntOrAuto { .. } => text.parse().ok().map(ParamValue::Int),
            ParamRange::Float { .. } => text.parse::<f32>().ok().map(|x| ParamValue::Float(f64::from(x))),
            ParamRange::Choice(words) => words.iter().find(|w| **w == text).map(|w| ParamValue::Word(w)),
        }
    }
}

impl fmt::Display for ParamRange {
    /// `1..=64`, `>= 0`, `auto or 0..=63`, `auto|greedy|ploc`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ParamRange::Int { min, max: Some(max) } => write!(f, "{min}..={max}"),
            ParamRange::Int { min, max: None } => write!(f, ">= {min}"),
            ParamRange::IntOrAuto { min, max } => write!(f, "auto or {min}..={max}"),
            ParamRange::Float { min, max: Some(max) } => write!(f, "{min}..={max}"),
            ParamRange::Float { min, max: None } => write!(f, ">= {min}"),
            ParamRange::Choice(words) => f.write_str(&words.join("|")),
        }
    }
}

/// The value of one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamValue {
    /// A whole number.
    Int(i64),
    /// A number (costs); single precision in the structures, widened here.
    Float(f64),
    /// One of a [`ParamRange::Choice`]'s words.
    Word(&'static str),
    /// Chosen by the structure from the input (see [`ParamRange::IntOrAuto`]).
    Auto,
}

impl ParamValue {
    /// A count or depth as a value (saturating: a field set directly past `i64::MAX` still reads as
    /// out of range, with its size).
    pub(crate) fn count(n: usize) -> ParamValue {
        ParamValue::Int(i64::try_from(n).unwrap_or(i64::MAX))
    }
    /// The value as an index or count (0 for anything else: only called where the range is integral).
    pub(crate) fn as_usize(&self) -> usize {
        match *self {
            ParamValue::Int(x) => usize::try_from(x).unwrap_or(0),
            _ => 0,
        }
    }
    /// The value as a cost (0 for anything else: only called where the range is a number).
    pub(crate) fn as_f32(&self) -> f32 {
        match *self {
            ParamValue::Float(x) => x as f32,
            _ => 0.0,
        }
    }
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Int(x) => write!(f, "{x}"),
            // Costs are single precision: shown as the f32 they are, `0.2` rather than its f64 widening.
            ParamValue::Float(x) => write!(f, "{}", *x as f32),
            ParamValue::Word(w) => f.write_str(w),
            ParamValue::Auto => f.write_str("auto"),
        }
    }
}

/// One build parameter of a structure: its key on the command line (`--accel-param KEY=VALUE`), what
/// it means and the values it accepts. Its default is the value in the structure's default
/// configuration ([`super::AccelConfig::get`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// The key, e.g. `leaf`.
    pub key: &'static str,
    /// One line saying what it does.
    pub about: &'static str,
    /// The values it accepts.
    pub range: ParamRange,
}

/// A `*Params` struct, read and written by key. Implementations only map keys to fields: values reach
/// [`ParamSet::put`] already parsed and inside their [`ParamSpec::range`].
#[doc(hidden)]
pub trait ParamSet {
    /// The parameters, in the order they are listed.
    fn specs(&self) -> &'static [ParamSpec];
    /// The value of `key`, `None` for a key not in [`ParamSet::specs`].
    fn get(&self, key: &str) -> Option<ParamValue>;
    /// Sets `key` (one of [`ParamSet::specs`]) to `value` (inside its range).
    fn put(&mut self, key: &str, value: ParamValue);
}

/// Sets `key` of `params` (a structure of `kind`) from the text `value`: an unknown key, a value that
/// does not read, or one outside the range is an error naming them.
pub(crate) fn set(kind: AccelKind, params: &mut dyn ParamSet, key: &str, value: &str) -> Result<(), ConfigError> {
    let key = key.trim();
    let spec = params
        .specs()
        .iter()
        .find(|s| s.key == key)
        .ok_or_else(|| ConfigError::UnknownParam { kind, key: key.to_string() })?;
    let text = value.trim();
    let err = |outside: bool| {
        let (key, value, range) = (key.to_string(), text.to_string(), spec.range);
        if outside {
            ConfigError::OutOfRange { key, value, range }
        } else {
            ConfigError::BadValue { key, value, range }
        }
    };
    let v = spec.range.read(text).ok_or_else(|| err(false))?;
    if !spec.range.contains(&v) {
        return Err(err(true));
    }
    params.put(spec.key, v);
    Ok(())
}

/// Checks that every parameter of `params` lies inside its range (fields can be set directly, past
/// [`set`]'s checks).
pub(crate) fn check(params: &dyn ParamSet) -> Result<(), ConfigError> {
    for spec in params.specs() {
        let v = params.get(spec.key).unwrap_or(ParamValue::Auto);
        if !spec.range.contains(&v) {
            return Err(ConfigError::OutOfRange { key: spec.key.to_string(), value: v.to_string(), range: spec.range });
        }
    }
    Ok(())
}

/// What is wrong with a structure's name or parameters.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ConfigError {
    /// No structure has this name.
    UnknownKind {
        /// The name given.
        name: String,
    },
    /// The structure has no parameter of this key.
    UnknownParam {
        /// The structure.
        kind: AccelKind,
        /// The key given.
        key: String,
    },
    /// A parameter was not written `KEY=VALUE`.
    NotKeyValue {
        /// The text given.
        text: String,
    },
    /// A parameter was not written `KIND:KEY=VALUE`.
    NotKindKeyValue {
        /// The text given.
        text: String,
    },
    /// The value does not read as the parameter's type (not a number, not one of its words).
    BadValue {
        /// The parameter.
        key: String,
        /// The value given.
        value: String,
        /// What it accepts.
        range: ParamRange,
    },
    /// The value reads but lies outside the parameter's range.
    OutOfRange {
        /// The parameter.
        key: String,
        /// The value given.
        value: String,
        /// What it accepts.
        range: ParamRange,
    },
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConfigError::UnknownKind { name } => {
                let names: Vec<_> = AccelKind::ALL.iter().map(|k| k.name()).collect();
                write!(f, "unknown acceleration structure '{name}' (expected one of: {})", names.join(", "))
            }
            ConfigError::UnknownParam { kind, key } => {
                let keys: Vec<_> = kind.params().iter().map(|s| s.key).collect();
                if keys.is_empty() {
                    write!(f, "{kind} takes no parameters (got '{key}')")
                } else {
                    write!(f, "{kind} has no parameter '{key}' (it has: {})", keys.join(", "))
                }
            }
            ConfigError::NotKeyValue { text } => write!(f, "'{text}' is not KEY=VALUE"),
            ConfigError::NotKindKeyValue { text } => write!(f, "'{text}' is not KIND:KEY=VALUE"),
            ConfigError::BadValue { key, value, range } => {
                write!(f, "parameter '{key}': cannot read '{value}' (expected {range})")
            }
            ConfigError::OutOfRange { key, value, range } => {
                write!(f, "parameter '{key}': {value} is outside its range {range}")
            }
        }
    }
}

impl std::error::Error for ConfigError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_ranges_display_and_contain_their_bounds() {
        let leaf = ParamRange::Int { min: 1, max: Some(64) };
        assert_eq!(leaf.to_string(), "1..=64");
        assert!(leaf.contains(&ParamValue::Int(1)) && leaf.contains(&ParamValue::Int(64)));
        assert!(!leaf.contains(&ParamValue::Int(0)) && !leaf.contains(&ParamValue::Int(65)));
        let cost = ParamRange::Float { min: 0.0, max: None };
        assert_eq!(cost.to_string(), ">= 0");
        assert!(cost.contains(&ParamValue::Float(0.0)) && cost.contains(&ParamValue::Float(1e30)));
        assert!(!cost.contains(&ParamValue::Float(-5.0)) && !cost.contains(&ParamValue::Float(f64::NAN)));
        assert!(!cost.contains(&ParamValue::Float(f64::INFINITY)));
        let depth = ParamRange::IntOrAuto { min: 0, max: 63 };
        assert_eq!(depth.to_string(), "auto or 0..=63");
        assert!(depth.contains(&ParamValue::Auto) && !depth.contains(&ParamValue::Int(64)));
        let method = ParamRange::Choice(&["auto", "ploc"]);
        assert_eq!(method.to_string(), "auto|ploc");
        assert!(method.contains(&ParamValue::Word("ploc")) && !method.contains(&ParamValue::Word("x")));
        assert!(!leaf.contains(&ParamValue::Float(3.0)), "a value of another type is outside");
    }

    #[test]
    fn params_read_parses_each_type() {
        assert_eq!(ParamRange::Int { min: 0, max: None }.read(" 12 "), Some(ParamValue::Int(12)));
        assert_eq!(ParamRange::Int { min: 0, max: None }.read("-1"), Some(ParamValue::Int(-1)));
        assert_eq!(ParamRange::Int { min: 0, max: None }.read("1.5"), None);
        assert_eq!(ParamRange::IntOrAuto { min: 0, max: 9 }.read("auto"), Some(ParamValue::Auto));
        assert_eq!(ParamRange::Float { min: 0.0, max: None }.read("0.5"), Some(ParamValue::Float(0.5)));
        assert_eq!(ParamValue::Float(f64::from(0.2f32)).to_string(), "0.2");
        assert_eq!(ParamRange::Float { min: 0.0, max: None }.read("half"), None);
        assert_eq!(ParamRange::Choice(&["a", "b"]).read("b"), Some(ParamValue::Word("b")));
    }
}
