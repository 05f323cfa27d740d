//! Pruning Whitted ray trees by the weight their rays carry: adaptive tree-depth control (Hall and
//! Greenberg, "A Testbed for Realistic Image Synthesis", 1983), with a bound on what it may change.
//!
//! Every glass hit spawns a reflection and a refraction, so a camera sample's ray tree can hold
//! `Σ b^k` rays for `k` up to the recursion depth `D` (`b` lobes per hit): 10^14 for glass inside
//! mirrors at depth 64 (about 10^13 in a closed mirror box, whose rays never escape). Where that full tree fits in [`TREE_BUDGET`] rays (every shared course scene:
//! depth 6 and two lobes make 127), nothing here applies and the tree is traced whole. Beyond it:
//!
//! - **The rule.** A ray of weight `w` (the product of the lobe weights above it, largest channel) with
//!   `r` bounces left brings back at most `w Λ_r`, where `Λ_r = ℓ Σ_{j≤r} W^j`: `ℓ` bounds the radiance
//!   one surface sends (ambient, emission and every light's irradiance bound times the material's
//!   `k_d + k_s`, over all materials; [`crate::light::Light::irradiance_bound`] from the geometry's
//!   clearance around each light) and `W` the sum of a hit's lobe weights. The branch is not traced when
//!   `w Λ_r ≤ ε`, with `ε` = [`PRUNED_LEVELS`] of an 8-bit level over `b` [`TREE_BUDGET`].
//! - **The bound.** Every ray of a tree has at most `b` children, so a tree of at most [`TREE_BUDGET`]
//!   traced rays prunes at most `b` times that many branches, which together change the sample, and so
//!   the pixel (a mean of samples), by at most [`PRUNED_LEVELS`] of a level of the linear 8-bit image:
//!   a value moves only where it lies that close to a rounding boundary, and then by one level.
//! - **The budget.** A sample first traces its pruned tree whole, counting; should it pass
//!   [`TREE_BUDGET`] rays, it is traced again from the same random numbers with the budget shared out
//!   ([`Shares`]): each hit hands what its allowance leaves to its lobes in proportion to their weights,
//!   passing on what a lobe's tree leaves unused, and a lobe given less than one ray is dropped, so the
//!   lightest branches go first. A sample thus traces at most twice the budget at any depth; those that
//!   dropped branches are counted, and a warning after the render gives the count.
//! - **The warning.** At depth `k` the weights sum to at most `W^k` and every traced ray weighs more
//!   than `ε / Λ_{D-k}`, so at most `min(b^k, W^k Λ_{D-k} / ε)` rays are traced there
//!   ([`TreePlan::pruned_bound`]). Where that sum exceeds the budget, or no `ℓ` is known (a light that
//!   surfaces touch, an environment map, textures, BRDF models: nothing is pruned then), a sample may
//!   have to drop branches, and [`TreePlan::warning`] says so before the render.
//!
//! Pruning changes which random numbers the rest of a tree draws, so it is confined to trees that need
//! it; where it applies it is deterministic (a branch's fate depends on its weight alone), so images stay
//! the same on any thread count. Cost: one multiply and compare per spawned ray.

use crate::material::Lobe;
use crate::scene::Scene;

/// The most rays one camera sample's Whitted tree traces in each of its (at most two) passes.
pub const TREE_BUDGET: u32 = 4096;
/// The most all pruned branches together may change a pixel, in levels of the linear 8-bit image.
pub const PRUNED_LEVELS: f32 = 1.0 / 16.0;
/// Triangles measured exactly around each light when bounding its irradiance (the rest by boxes).
const CLEARANCE_WORK: usize = 4_000_000;

/// The pruning rule of a scene whose full trees exceed the budget.
#[derive(Debug, Clone, PartialEq)]
pub struct Pruning {
    /// `Λ_r` for `r` = 0 ..= the recursion depth, in radiance (infinite where unknown).
    bound: Vec<f32>,
    /// `ε`, in radiance.
    epsilon: f32,
}

impl Pruning {
    /// Whether a ray of `weight` with `bounces_left` cannot change the image visibly.
    #[inline]
    pub fn prunes(&self, weight: f32, bounces_left: u32) -> bool {
        weight * self.bound[bounces_left as usize] <= self.epsilon
    }
}

/// How a scene's Whitted trees are traced.
#[derive(Debug, Clone, PartialEq)]
pub struct TreePlan {
    /// The most lobes a hit spawns.
    pub branching: usize,
    /// The recursion depth.
    pub depth: u32,
    /// Rays of a full tree: `Σ_{k≤D} b^k`.
    pub full: f64,
    /// The rule, when the full tree exceeds [`TREE_BUDGET`]; its bounds are infinite (nothing is pruned,
    /// only the budget applies) when [`TreePlan::unbounded`] says why.
    pub pruning: Option<Pruning>,
    /// Rays a sample may trace under the rule (at most the full tree); `None` without a radiance bound.
    pub pruned_bound: Option<f64>,
    /// Why the scene's radiance has no known bound.
    pub unbounded: Option<&'static str>,
}

impl TreePlan {
    /// The plan for `scene`'s Whitted trees.
    pub fn of(scene: &Scene) -> TreePlan {
        let layers = || scene.materials.iter().filter_map(|m| m.layer.as_ref());
        let branching = layers().map(|l| l.max_lobes()).max().unwrap_or(0);
        let depth = scene.max_depth;
        let full = (0..=depth).map(|k| (branching as f64).powi(k as i32)).sum::<f64>();
        let mut plan = TreePlan { branching, depth, full, pruning: None, pruned_bound: None, unbounded: None };
        if full <= TREE_BUDGET as f64 {
            plan.pruned_bound = Some(full);
            return plan;
        }
        let w = layers().map(|l| l.weight_bound()).fold(0.0f32, f32::max);
        let local = local_bound(scene);
        plan.unbounded = local.err();
        let local = local.unwrap_or(f32::INFINITY);
        // Λ_r = ℓ Σ_{j≤r} W^j.
        let mut sum = 0.0f32;
        let bound: Vec<f32> = (0..=depth)
            .map(|r| {
                sum += w.powi(r as i32);
                local * sum
            })
            .collect();
        // One level of the linear 8-bit image is 1/255 of white, which is 1 / radiance_scale radiance.
        let level = 1.0 / (255.0 * scene.radiance_scale);
        let epsilon = PRUNED_LEVELS * level / (branching as f32 * TREE_BUDGET as f32);
        if local.is_finite() {
            let rays = (0..=depth).map(|k| {
                let heaviest = (w as f64).powi(k as i32) * bound[(depth - k) as usize] as f64 / epsilon as f64;
                (branching as f64).powi(k as i32).min(if k == 0 { 1.0 } else { heaviest })
            });
            plan.pruned_bound = Some(rays.sum());
        }
        plan.pruning = Some(Pruning { bound, epsilon });
        plan
    }

    /// The warning before a render whose samples may need more rays than the budget, naming why.
    pub fn warning(&self) -> Option<String> {
        let needs = self.pruned_bound.unwrap_or(self.full);
        if needs <= TREE_BUDGET as f64 {
            return None;
        }
        let why = match self.unbounded {
            Some(reason) => format!("no branch can be shown too weak to matter ({reason})"),
            None => format!(
                "pruning the branches too weak to change a pixel by 1/{} of a level leaves up to {needs:.3e}",
                1.0 / PRUNED_LEVELS
            ),
        };
        Some(format!(
            "a sample's ray tree may hold {:.3e} rays (recursion depth {}, {} rays per hit); {why}: a sample \
             traces at most {TREE_BUDGET}, and one that needs more drops its lightest branches, which may show",
            self.full, self.depth, self.branching
        ))
    }
}

/// The rays a hit's lobes share: what its allowance leaves after the hit's own ray, handed out in
/// proportion to the lobes' weights, and what a lobe's tree leaves unused passed on to the lobes after
/// it. A lobe whose share is under one ray is dropped: a tree needing more than its budget loses its
/// lightest branches first.
pub struct Shares {
    pool: f32,
    weight_left: f32,
}

impl Shares {
    /// The shares of `lobes` under a ray's `allowance`.
    pub fn new(allowance: f32, lobes: &[Lobe]) -> Shares {
        Shares { pool: allowance - 1.0, weight_left: lobes.iter().map(|l| l.weight.max_element()).sum() }
    }

    /// The next lobe's allowance (its weight is `w`), or `None` under one ray.
    pub fn take(&mut self, w: f32) -> Option<f32> {
        let share = if self.weight_left > 0.0 { self.pool * (w / self.weight_left).min(1.0) } else { self.pool };
        self.weight_left -= w;
        (share >= 1.0).then_some(share)
    }

    /// Whether there is no budget to share (the first pass of a tree).
    pub fn unlimited(&self) -> bool {
        self.pool.is_infinite()
    }

    /// The next lobe is pruned: it takes nothing.
    pub fn skip(&mut self, w: f32) {
        self.weight_left -= w;
    }

    /// The last lobe's tree traced `rays` rays.
    pub fn spent(&mut self, rays: u32) {
        self.pool -= rays as f32;
    }
}

/// `ℓ`: the most radiance one surface sends back towards a ray, largest channel; or why none is known.
fn local_bound(scene: &Scene) -> Result<f32, &'static str> {
    if scene.environment.is_some() {
        return Err("an environment map");
    }
    if !scene.textures.is_empty() {
        return Err("textures");
    }
    if scene.materials.iter().any(|m| m.brdf.is_some()) {
        return Err("a BRDF model");
    }
    let clearance = |q| scene.geometry.clearance(q, CLEARANCE_WORK);
    let mut irradiance = 0.0f32;
    for light in &scene.lights {
        irradiance += light.irradiance_bound(&clearance).ok_or("a light that surfaces come arbitrarily near")?;
    }
    let emission = scene.object_emission.iter().flatten().map(|c| c.max_element()).fold(0.0f32, f32::max);
    let ambient = scene.ambient.max_element();
    let local = scene
        .materials
        .iter()
        .map(|m| m.ambient.max_element() * ambient + (m.diffuse + m.specular).max_element() * irradiance)
        .fold(0.0f32, f32::max)
        + emission;
    if local.is_finite() {
        Ok(local)
    } else {
        Err("radiance beyond the range of 32-bit floats")
    }
}
