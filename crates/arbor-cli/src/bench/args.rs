//! The flags of `arbor bench` and the values they parse into, shared by both forms of the command.

use std::path::PathBuf;

use arbor::accel::{AccelConfig, AccelKind, ConfigError, KindParam};
use clap::{Args, ValueEnum};

use crate::Failure;

/// Arguments of `arbor bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// A scene file (.xml, .json; its first camera at its resolution), a mesh file (.ply, .obj, .off;
    /// framed by a default camera from the +z side, 1024x1024), or `sphere:N`, a generated unit sphere
    /// of about N triangles (e.g. sphere:1000000).
    pub input: String,
    /// Structures to compare: `all`, or a comma-separated list (brute,octree,kdtree,bvh-median,bvh-sah,
    /// bvh-bottom-up) [default: all; with --ray-dir: bvh-sah].
    #[arg(long, value_parser = parse_accel_list)]
    pub accel: Option<AccelList>,
    /// A build parameter for one structure, KIND:KEY=VALUE (e.g. octree:leaf=16; repeatable).
    #[arg(long = "accel-param", value_name = "KIND:KEY=VALUE")]
    pub accel_params: Vec<String>,
    /// Which ray sets to time.
    #[arg(long, value_enum, default_value_t = RaySets::Both)]
    pub rays: RaySets,
    /// A folder of ray files written by `peerbench --dump-rays DIR` for the mesh file INPUT: trace
    /// exactly the peers' rays and print peerbench's line format (see docs/performance.md).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["size", "brute_rays", "json", "no_limits"])]
    pub ray_dir: Option<PathBuf>,
    /// With --ray-dir: which query to time on the peers' rays: closest hits, or any hits (shadow-ray
    /// queries up to each ray's t_max; `peer=arbor-KIND-any`, judged by whether the reference hit).
    #[arg(long, value_enum, default_value_t = Query::Closest, requires = "ray_dir")]
    pub query: Query,
    /// Image size WxH, overriding the camera's resolution (the window stays: same view, fewer rays).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Timed passes over each ray set; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub runs: u32,
    /// Rays per set traced by brute force (default: as many as 5e8 triangle tests allow, 64 to 4096).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub brute_rays: Option<u64>,
    #[command(flatten)]
    pub threads: crate::threads::ThreadsArg,
    /// One JSON document on standard output instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Lift the limits on image size, recursion depth and the pixels of the images a scene reads (as
    /// `arbor render --no-limits`).
    #[arg(long)]
    pub no_limits: bool,
}

/// The query `--query` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Query {
    /// `intersect` and `intersect_many`.
    Closest,
    /// `occluded` and `occluded_many`.
    Any,
}

/// The ray sets `--rays` names.
#[derive(Clone, Copy, PartialEq, Eq, Debug, ValueEnum)]
pub enum RaySets {
    /// Camera rays through the pixels.
    Primary,
    /// One diffuse bounce from every primary hit.
    Diffuse,
    /// Both sets.
    Both,
}

impl RaySets {
    /// True when the set named `name` ("primary" or "diffuse") is among these.
    pub fn has(self, name: &str) -> bool {
        match self {
            RaySets::Both => true,
            RaySets::Primary => name == "primary",
            RaySets::Diffuse => name == "diffuse",
        }
    }
}

/// The structures named by `--accel`.
#[derive(Clone)]
pub struct AccelList(pub Vec<AccelKind>);

fn parse_accel_list(s: &str) -> Result<AccelList, String> {
    if s.trim() == "all" {
        return Ok(AccelList(AccelKind::ALL.to_vec()));
    }
    let mut kinds: Vec<AccelKind> = Vec::new();
    for name in s.split(',').map(str::trim) {
        let kind: AccelKind = name.parse().map_err(|e: ConfigError| e.to_string())?;
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    Ok(AccelList(kinds))
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("'{s}' is not WxH (e.g. 512x512)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?);
    if w == 0 || h == 0 || w as u64 * h as u64 > 1 << 24 {
        return Err(format!("image size {w}x{h} must be at least 1x1 and at most 16 M pixels"));
    }
    Ok((w, h))
}

/// One configuration per structure, with the `--accel-param KIND:KEY=VALUE` entries of its kind; any
/// entry that does not parse, names a structure not benchmarked, or does not apply is a usage error.
pub fn specs(kinds: &[AccelKind], params: &[String]) -> Result<Vec<AccelConfig>, Failure> {
    let mut configs: Vec<AccelConfig> = kinds.iter().map(|&k| AccelConfig::from(k)).collect();
    for p in params {
        let usage = |msg: String| Failure::Usage(msg);
        let param: KindParam = p.parse().map_err(|e| match e {
            ConfigError::NotKindKeyValue { .. } => usage(format!("--accel-param {e}")),
            e => usage(format!("--accel-param '{p}': {e}")),
        })?;
        let config = configs.iter_mut().find(|c| c.kind() == param.kind);
        let config = config
            .ok_or_else(|| usage(format!("--accel-param '{p}': {} is not benchmarked (see --accel)", param.kind)))?;
        config.set(&param.key, &param.value).map_err(|e| usage(format!("--accel-param '{p}': {e}")))?;
    }
    Ok(configs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_ray_sets_select_by_name() {
        assert!(RaySets::Both.has("primary") && RaySets::Both.has("diffuse"));
        assert!(RaySets::Primary.has("primary") && !RaySets::Primary.has("diffuse"));
        assert!(RaySets::Diffuse.has("diffuse") && !RaySets::Diffuse.has("primary"));
    }

    #[test]
    fn bench_size_parses_and_bounds() {
        assert_eq!(parse_size("40x30"), Ok((40, 30)));
        assert_eq!(parse_size("0x30"), Err("image size 0x30 must be at least 1x1 and at most 16 M pixels".into()));
        assert_eq!(parse_size("40"), Err("'40' is not WxH (e.g. 512x512)".into()));
    }
}
