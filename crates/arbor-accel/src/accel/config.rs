//! One typed configuration for every structure: [`AccelConfig`] is the structure and its parameters
//! struct, parsed from its name (`"kdtree".parse()`), tuned by key (`config.set("leaf", "8")`) with each
//! value checked against its documented range, and turned into a built structure by the one factory
//! (pbrt's `CreateAccelerator`). [`KindParam`] reads the bench's per-structure `KIND:KEY=VALUE`.
//!
//! Every operation that depends on the structure is one `match` here; the parameters themselves are
//! tables in each structure's module ([`super::ParamSpec`]), read by the shared code of `params.rs`.

use std::fmt;
use std::str::FromStr;

use super::params::{self, ConfigError, ParamSet, ParamSpec, ParamValue};
use super::{Accel, AccelKind, BottomUpParams, BruteForce, Bvh, BvhParams, KdTree, KdTreeParams, MedianParams};
use super::{Octree, OctreeParams, Primitives};

/// A structure and its build parameters. [`Default`] is the binned-SAH BVH with its default
/// parameters; a name parses into that structure with its defaults.
///
/// ```
/// use arbor_accel::accel::{AccelConfig, AccelKind};
///
/// let mut config: AccelConfig = "octree".parse()?;
/// config.set("leaf", "4")?;
/// config.set("depth", "12")?;
/// assert_eq!(config.kind(), AccelKind::Octree);
/// assert_eq!(config.get("depth").unwrap().to_string(), "12");
///
/// // Out of range: the error names the parameter, the value and the range.
/// let err = config.set("depth", "99").unwrap_err();
/// assert_eq!(err.to_string(), "parameter 'depth': 99 is outside its range 0..=16");
/// assert_eq!(AccelConfig::default().kind(), AccelKind::BvhSah);
/// # Ok::<(), arbor_accel::accel::ConfigError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum AccelConfig {
    /// Brute force: no structure, no parameters.
    Brute,
    /// Regular octree.
    Octree(OctreeParams),
    /// Kd-tree with SAH splits.
    KdTree(KdTreeParams),
    /// BVH split at the median centroid.
    BvhMedian(MedianParams),
    /// BVH with binned SAH splits (the default).
    BvhSah(BvhParams),
    /// BVH built bottom-up (greedy agglomerative or PLOC).
    BvhBottomUp(BottomUpParams),
}

impl Default for AccelConfig {
    fn default() -> Self {
        AccelConfig::BvhSah(BvhParams::default())
    }
}

impl From<AccelKind> for AccelConfig {
    /// `kind` with its default parameters.
    fn from(kind: AccelKind) -> Self {
        match kind {
            AccelKind::Brute => AccelConfig::Brute,
            AccelKind::Octree => AccelConfig::Octree(OctreeParams::default()),
            AccelKind::KdTree => AccelConfig::KdTree(KdTreeParams::default()),
            AccelKind::BvhMedian => AccelConfig::BvhMedian(MedianParams::default()),
            AccelKind::BvhSah => AccelConfig::BvhSah(BvhParams::default()),
            AccelKind::BvhBottomUp => AccelConfig::BvhBottomUp(BottomUpParams::default()),
        }
    }
}

impl FromStr for AccelConfig {
    type Err = ConfigError;
    /// A structure's name ([`AccelKind::name`]) with its default parameters.
    fn from_str(s: &str) -> Result<Self, ConfigError> {
        s.parse::<AccelKind>().map(AccelConfig::from)
    }
}

impl AccelConfig {
    /// Which structure this builds.
    pub fn kind(&self) -> AccelKind {
        match self {
            AccelConfig::Brute => AccelKind::Brute,
            AccelConfig::Octree(_) => AccelKind::Octree,
            AccelConfig::KdTree(_) => AccelKind::KdTree,
            AccelConfig::BvhMedian(_) => AccelKind::BvhMedian,
            AccelConfig::BvhSah(_) => AccelKind::BvhSah,
            AccelConfig::BvhBottomUp(_) => AccelKind::BvhBottomUp,
        }
    }

    /// The parameters of this structure, with their ranges (empty for brute force).
    pub fn params(&self) -> &'static [ParamSpec] {
        self.param_set().map_or(&[], |p| p.specs())
    }

    /// The current value of parameter `key`, `None` when the structure has no such parameter.
    pub fn get(&self, key: &str) -> Option<ParamValue> {
        self.param_set()?.get(key.trim())
    }

    /// Sets parameter `key` from its text. An error names a key the structure does not have, a value
    /// that does not read, or one outside the parameter's range; the configuration is then unchanged.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), ConfigError> {
        let kind = self.kind();
        match self.param_set_mut() {
            Some(p) => params::set(kind, p, key, value),
            None => Err(ConfigError::UnknownParam { kind, key: key.trim().to_string() }),
        }
    }

    /// [`AccelConfig::set`] from `KEY=VALUE`.
    pub fn set_pair(&mut self, pair: &str) -> Result<(), ConfigError> {
        let (key, value) = pair.split_once('=').ok_or_else(|| ConfigError::NotKeyValue { text: pair.to_string() })?;
        self.set(key, value)
    }

    /// This configuration with `KEY=VALUE` pairs applied in order (the command line's
    /// `--accel-param`s).
    pub fn with_pairs<'a>(mut self, pairs: impl IntoIterator<Item = &'a str>) -> Result<Self, ConfigError> {
        for pair in pairs {
            self.set_pair(pair)?;
        }
        Ok(self)
    }

    /// Checks that every parameter lies in its range. [`AccelConfig::set`] checks as it goes; this
    /// catches values written into the parameters structs directly, and building runs it first.
    pub fn check(&self) -> Result<(), ConfigError> {
        self.param_set().map_or(Ok(()), params::check)
    }

    /// Builds this structure over `prims` behind the internal contract (the renderer's two-level scene
    /// and benchmarks use it; others use [`super::Structure`]). In debug builds the result is validated
    /// before it is returned.
    #[doc(hidden)]
    pub fn build_accel<P: Primitives + ?Sized + 'static>(&self, prims: &P) -> Result<Box<dyn Accel<P>>, ConfigError> {
        self.check()?;
        let accel: Box<dyn Accel<P>> = match self {
            AccelConfig::Brute => Box::new(BruteForce::build(prims)),
            AccelConfig::Octree(p) => Box::new(Octree::build(prims, p)),
            AccelConfig::KdTree(p) => Box::new(KdTree::build(prims, p)),
            AccelConfig::BvhMedian(p) => Box::new(Bvh::build_median(prims, p)),
            AccelConfig::BvhSah(p) => Box::new(Bvh::build_sah(prims, p)),
            AccelConfig::BvhBottomUp(p) => Box::new(Bvh::build_bottom_up(prims, p)),
        };
        #[cfg(debug_assertions)]
        if let Err(e) = accel.validate(prims) {
            panic!("{} built an invalid structure: {e}", self.kind());
        }
        Ok(accel)
    }

    fn param_set(&self) -> Option<&dyn ParamSet> {
        match self {
            AccelConfig::Brute => None,
            AccelConfig::Octree(p) => Some(p),
            AccelConfig::KdTree(p) => Some(p),
            AccelConfig::BvhMedian(p) => Some(p),
            AccelConfig::BvhSah(p) => Some(p),
            AccelConfig::BvhBottomUp(p) => Some(p),
        }
    }

    fn param_set_mut(&mut self) -> Option<&mut dyn ParamSet> {
        match self {
            AccelConfig::Brute => None,
            AccelConfig::Octree(p) => Some(p),
            AccelConfig::KdTree(p) => Some(p),
            AccelConfig::BvhMedian(p) => Some(p),
            AccelConfig::BvhSah(p) => Some(p),
            AccelConfig::BvhBottomUp(p) => Some(p),
        }
    }
}

impl fmt::Display for AccelConfig {
    /// The name, then every parameter that differs from the default: `octree leaf=4 depth=12`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind().name())?;
        let defaults = AccelConfig::from(self.kind());
        for spec in self.params() {
            match (self.get(spec.key), defaults.get(spec.key)) {
                (Some(v), d) if Some(v) != d => write!(f, " {}={v}", spec.key)?,
                _ => {}
            }
        }
        Ok(())
    }
}

/// A parameter for one structure among several, written `KIND:KEY=VALUE` (`arbor bench
/// --accel-param kdtree:depth=20`).
///
/// ```
/// use arbor_accel::accel::{AccelConfig, AccelKind, KindParam};
///
/// let p: KindParam = "kdtree:empty-bonus=0.5".parse()?;
/// assert_eq!((p.kind, p.key.as_str(), p.value.as_str()), (AccelKind::KdTree, "empty-bonus", "0.5"));
/// let mut config = AccelConfig::from(p.kind);
/// config.set(&p.key, &p.value)?;
/// assert!("kdtree-leaf=3".parse::<KindParam>().is_err());
/// # Ok::<(), arbor_accel::accel::ConfigError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KindParam {
    /// The structure the parameter is for.
    pub kind: AccelKind,
    /// The parameter's key.
    pub key: String,
    /// Its value, as written.
    pub value: String,
}

impl FromStr for KindParam {
    type Err = ConfigError;
    fn from_str(s: &str) -> Result<Self, ConfigError> {
        let not = || ConfigError::NotKindKeyValue { text: s.to_string() };
        let (kind, pair) = s.split_once(':').ok_or_else(not)?;
        let (key, value) = pair.split_once('=').ok_or_else(not)?;
        Ok(KindParam { kind: kind.trim().parse()?, key: key.trim().to_string(), value: value.trim().to_string() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::ParamRange;

    #[test]
    fn config_parses_every_kind_by_name_with_its_defaults() {
        for &kind in AccelKind::ALL {
            let c: AccelConfig = kind.name().parse().unwrap();
            assert_eq!(c, AccelConfig::from(kind));
            assert_eq!(c.kind(), kind);
            assert_eq!(c.to_string(), kind.name(), "defaults are not listed");
            assert!(c.check().is_ok());
        }
        assert_eq!(
            "quadtree".parse::<AccelConfig>().unwrap_err().to_string(),
            "unknown acceleration structure 'quadtree' (expected one of: brute, octree, kdtree, bvh-median, \
             bvh-sah, bvh-bottom-up)"
        );
    }

    #[test]
    fn config_set_applies_known_keys_and_refuses_others() {
        let c = AccelConfig::default().with_pairs(["leaf=4", "bins=24"]).unwrap();
        let AccelConfig::BvhSah(p) = &c else { panic!("{c:?}") };
        assert_eq!((p.max_leaf_prims, p.bins), (4, 24));
        assert_eq!(c.to_string(), "bvh-sah leaf=4 bins=24");
        let err = AccelConfig::default().with_pairs(["depth=3"]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "bvh-sah has no parameter 'depth' (it has: leaf, bins, traversal-cost, intersection-cost, leaf-block)"
        );
        let err = AccelConfig::from(AccelKind::Octree).with_pairs(["leaf=many"]).unwrap_err();
        assert_eq!(err.to_string(), "parameter 'leaf': cannot read 'many' (expected >= 1)");
        let err = AccelConfig::Brute.with_pairs(["leaf=1"]).unwrap_err();
        assert_eq!(err.to_string(), "brute takes no parameters (got 'leaf')");
        assert_eq!(AccelConfig::Brute.set_pair("x").unwrap_err().to_string(), "'x' is not KEY=VALUE");
        let err = AccelConfig::from(AccelKind::BvhBottomUp).with_pairs(["method=best"]).unwrap_err();
        assert_eq!(err.to_string(), "parameter 'method': cannot read 'best' (expected auto|greedy|ploc)");
    }

    /// The values the old string parameters accepted silently (and clamped, or used as given).
    #[test]
    fn config_refuses_values_outside_their_range() {
        let cases = [
            ("bvh-sah", "leaf=0", "parameter 'leaf': 0 is outside its range 1..=64"),
            ("bvh-sah", "leaf=1000", "parameter 'leaf': 1000 is outside its range 1..=64"),
            ("bvh-sah", "bins=1", "parameter 'bins': 1 is outside its range 2..=32"),
            ("bvh-sah", "leaf-block=9", "parameter 'leaf-block': 9 is outside its range 1..=8"),
            ("bvh-sah", "traversal-cost=-5", "parameter 'traversal-cost': -5 is outside its range >= 0"),
            ("bvh-sah", "intersection-cost=inf", "parameter 'intersection-cost': inf is outside its range >= 0"),
            ("bvh-median", "leaf=65", "parameter 'leaf': 65 is outside its range 1..=64"),
            ("octree", "depth=99", "parameter 'depth': 99 is outside its range 0..=16"),
            ("octree", "leaf=0", "parameter 'leaf': 0 is outside its range >= 1"),
            ("octree", "traversal-cost=nan", "parameter 'traversal-cost': nan is outside its range >= 0"),
            ("kdtree", "empty-bonus=5", "parameter 'empty-bonus': 5 is outside its range 0..=1"),
            ("kdtree", "traversal-cost=-5", "parameter 'traversal-cost': -5 is outside its range >= 0"),
            ("kdtree", "depth=64", "parameter 'depth': 64 is outside its range auto or 0..=63"),
            ("bvh-bottom-up", "radius=0", "parameter 'radius': 0 is outside its range 1..=256"),
            ("bvh-bottom-up", "radius=257", "parameter 'radius': 257 is outside its range 1..=256"),
            ("bvh-bottom-up", "leaf=0", "parameter 'leaf': 0 is outside its range 1..=64"),
        ];
        for (kind, pair, message) in cases {
            let mut c: AccelConfig = kind.parse().unwrap();
            let before = c.clone();
            let err = c.set_pair(pair).unwrap_err();
            assert!(matches!(err, ConfigError::OutOfRange { .. }), "{kind} {pair}: {err:?}");
            assert_eq!(err.to_string(), message, "{kind} {pair}");
            assert_eq!(c, before, "{kind} {pair}: a refused value leaves the configuration as it was");
        }
    }

    #[test]
    fn config_accepts_the_ends_of_every_range() {
        for &kind in AccelKind::ALL {
            for spec in kind.params() {
                let ends: Vec<String> = match spec.range {
                    ParamRange::Int { min, max } => vec![min.to_string(), max.unwrap_or(min + 1000).to_string()],
                    ParamRange::IntOrAuto { min, max } => vec![min.to_string(), max.to_string(), "auto".into()],
                    ParamRange::Float { min, max } => vec![min.to_string(), max.unwrap_or(1e6).to_string()],
                    ParamRange::Choice(words) => words.iter().map(|w| w.to_string()).collect(),
                };
                for v in ends {
                    let mut c = AccelConfig::from(kind);
                    c.set(spec.key, &v).unwrap_or_else(|e| panic!("{kind} {}={v}: {e}", spec.key));
                    assert_eq!(c.get(spec.key).unwrap().to_string(), v, "{kind} {} reads back", spec.key);
                    assert!(c.check().is_ok());
                }
            }
        }
    }

    #[test]
    fn config_defaults_lie_in_their_ranges() {
        for &kind in AccelKind::ALL {
            let c = AccelConfig::from(kind);
            for spec in kind.params() {
                let v = c.get(spec.key).unwrap_or_else(|| panic!("{kind} {} has no value", spec.key));
                assert!(spec.range.contains(&v), "{kind} {} default {v} outside {}", spec.key, spec.range);
            }
        }
    }

    #[test]
    fn config_check_catches_fields_written_directly() {
        let c = AccelConfig::BvhSah(BvhParams { bins: 1, ..BvhParams::default() });
        assert_eq!(c.check().unwrap_err().to_string(), "parameter 'bins': 1 is outside its range 2..=32");
        let mesh = crate::geometry::TriangleMesh::default();
        assert!(c.build_accel(&mesh).is_err(), "building checks the parameters first");
        let c = AccelConfig::KdTree(KdTreeParams { empty_bonus: f32::NAN, ..KdTreeParams::default() });
        assert!(c.check().is_err());
        let c = AccelConfig::Octree(OctreeParams { max_leaf_prims: 0, ..OctreeParams::default() });
        assert_eq!(c.check().unwrap_err().to_string(), "parameter 'leaf': 0 is outside its range >= 1");
        let c = AccelConfig::BvhMedian(MedianParams { max_leaf_prims: usize::MAX });
        assert_eq!(
            c.check().unwrap_err().to_string(),
            format!("parameter 'leaf': {} is outside its range 1..=64", i64::MAX),
            "a huge count is reported as huge, not wrapped"
        );
    }

    #[test]
    fn config_kind_param_reads_kind_key_value() {
        let p: KindParam = " octree : depth = 12 ".parse().unwrap();
        assert_eq!(p, KindParam { kind: AccelKind::Octree, key: "depth".into(), value: "12".into() });
        assert_eq!("leaf=3".parse::<KindParam>().unwrap_err().to_string(), "'leaf=3' is not KIND:KEY=VALUE");
        assert_eq!("octree:leaf".parse::<KindParam>().unwrap_err().to_string(), "'octree:leaf' is not KIND:KEY=VALUE");
        assert!(matches!("tree:leaf=3".parse::<KindParam>(), Err(ConfigError::UnknownKind { .. })));
    }
}
