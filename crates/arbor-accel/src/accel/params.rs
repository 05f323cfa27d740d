//! Build parameters from the command line: `--accel octree --accel-param leaf=16 --accel-param depth=10`
//! becomes an [`AccelSpec`], and each structure's `*Params` struct takes the pairs it knows ([`Params`]),
//! refusing the others by name.

use std::str::FromStr;

use super::AccelKind;

/// A structure's build knobs, settable by name.
pub trait Params: Default {
    /// The keys it accepts, with a one-line description each.
    const KEYS: &'static [(&'static str, &'static str)];
    /// Sets `key` to `value`; an error says what is wrong in words a user understands.
    fn set(&mut self, key: &str, value: &str) -> Result<(), String>;
}

/// Parses `value` for parameter `key`.
pub fn parse_value<T: FromStr>(key: &str, value: &str) -> Result<T, String> {
    value.trim().parse().map_err(|_| format!("parameter '{key}': cannot read '{value}'"))
}

/// The error for a key a structure does not know.
pub fn unknown_key(kind: &str, key: &str, keys: &[(&str, &str)]) -> String {
    if keys.is_empty() {
        return format!("{kind} takes no parameters (got '{key}')");
    }
    let names: Vec<&str> = keys.iter().map(|(k, _)| *k).collect();
    format!("{kind} has no parameter '{key}' (it has: {})", names.join(", "))
}

/// Brute force's parameters: none.
#[derive(Debug, Default)]
pub struct NoParams;

impl Params for NoParams {
    const KEYS: &'static [(&'static str, &'static str)] = &[];
    fn set(&mut self, key: &str, _value: &str) -> Result<(), String> {
        Err(unknown_key("brute", key, Self::KEYS))
    }
}

/// A structure and the parameters given for it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AccelSpec {
    /// Which structure.
    pub kind: AccelKind,
    /// `key=value` pairs, in the order given.
    pub params: Vec<(String, String)>,
}

impl AccelSpec {
    /// `kind` with its default parameters.
    pub fn new(kind: AccelKind) -> Self {
        AccelSpec { kind, params: Vec::new() }
    }

    /// Adds parameters written `key=value`.
    pub fn with_params<'a>(mut self, pairs: impl IntoIterator<Item = &'a str>) -> Result<Self, String> {
        for pair in pairs {
            let (k, v) = pair.split_once('=').ok_or_else(|| format!("'{pair}' is not KEY=VALUE"))?;
            self.params.push((k.trim().to_string(), v.trim().to_string()));
        }
        Ok(self)
    }

    /// The parameters as the structure's own `*Params`.
    pub fn parse<T: Params>(&self) -> Result<T, String> {
        let mut p = T::default();
        for (k, v) in &self.params {
            p.set(k, v)?;
        }
        Ok(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{BvhParams, OctreeParams};

    #[test]
    fn params_parse_known_keys_and_refuse_others() {
        let spec = AccelSpec::new(AccelKind::BvhSah).with_params(["leaf=4", "bins=24"]).unwrap();
        let p: BvhParams = spec.parse().unwrap();
        assert_eq!((p.max_leaf_prims, p.bins), (4, 24));
        let bad = AccelSpec::new(AccelKind::BvhSah).with_params(["depth=3"]).unwrap();
        assert!(bad.parse::<BvhParams>().unwrap_err().contains("no parameter 'depth'"));
        let junk = AccelSpec::new(AccelKind::Octree).with_params(["leaf=many"]).unwrap();
        assert_eq!(junk.parse::<OctreeParams>().unwrap_err(), "parameter 'leaf': cannot read 'many'");
        assert!(AccelSpec::new(AccelKind::Brute).with_params(["x"]).is_err());
        let brute = AccelSpec::new(AccelKind::Brute).with_params(["leaf=1"]).unwrap();
        assert_eq!(brute.parse::<NoParams>().unwrap_err(), "brute takes no parameters (got 'leaf')");
    }
}
