//! PLACEHOLDER: the kdtree is being written; until then it answers through brute force.
use crate::accel::params::{parse_value, unknown_key, Params};
use crate::accel::{Accel, AccelStats, BruteForce, Hit, Primitives, TraversalCounts};
use crate::math::{Aabb, Ray};

/// Build parameters.
#[derive(Debug, Clone)]
pub struct KdTreeParams {
    /// Most primitives in a leaf.
    pub max_leaf_prims: usize,
    /// Deepest level.
    pub max_depth: usize,
}

impl Default for KdTreeParams {
    fn default() -> Self {
        KdTreeParams { max_leaf_prims: 8, max_depth: 16 }
    }
}

impl Params for KdTreeParams {
    const KEYS: &'static [(&'static str, &'static str)] =
        &[("leaf", "most primitives in a leaf"), ("depth", "deepest level")];
    fn set(&mut self, key: &str, value: &str) -> Result<(), String> {
        match key {
            "leaf" => self.max_leaf_prims = parse_value(key, value)?,
            "depth" => self.max_depth = parse_value(key, value)?,
            _ => return Err(unknown_key("kdtree", key, Self::KEYS)),
        }
        Ok(())
    }
}

/// The structure.
pub struct KdTree(BruteForce);

impl KdTree {
    /// Builds it.
    pub fn build<P: Primitives + ?Sized>(prims: &P, _params: &KdTreeParams) -> Self {
        KdTree(BruteForce::build(prims))
    }
}

impl<P: Primitives + ?Sized> Accel<P> for KdTree {
    fn bounds(&self) -> Aabb {
        Accel::<P>::bounds(&self.0)
    }
    fn intersect(&self, prims: &P, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.0.intersect(prims, ray, t_max)
    }
    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool {
        self.0.occluded(prims, ray, t_max)
    }
    fn stats(&self) -> AccelStats {
        Accel::<P>::stats(&self.0)
    }
    fn validate(&self, prims: &P) -> Result<(), String> {
        self.0.validate(prims)
    }
    fn intersect_counted(&self, prims: &P, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        self.0.intersect_counted(prims, ray, t_max, counts)
    }
    fn boxes_at_depth(&self, depth: usize) -> Vec<Aabb> {
        Accel::<P>::boxes_at_depth(&self.0, depth)
    }
}
