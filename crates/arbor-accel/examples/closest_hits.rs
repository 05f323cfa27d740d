//! Builds a UV sphere from plain arrays, builds every structure over it, traces a fan of rays through
//! each and prints the closest hits: every structure prints the same triangles at the same distances.
//!
//! Run with `cargo run -p arbor-accel --example closest_hits`.

use arbor_accel::accel::{AccelConfig, AccelKind, Structure};
use arbor_accel::geometry::TriangleMesh;
use arbor_accel::math::{Ray, Vec3};

/// A sphere of radius `r` at the origin: `rings` bands of latitude, `segments` of longitude.
fn uv_sphere(r: f32, rings: u32, segments: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            positions.push([r * theta.sin() * phi.cos(), r * theta.cos(), r * theta.sin() * phi.sin()]);
        }
    }
    let vertex = |i: u32, j: u32| i * segments + j % segments;
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (vertex(i, j), vertex(i, j + 1), vertex(i + 1, j), vertex(i + 1, j + 1));
            // Counter-clockwise seen from outside.
            triangles.push([a, b, c]);
            triangles.push([b, d, c]);
        }
    }
    (positions, triangles)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (positions, triangles) = uv_sphere(1.0, 24, 48);
    let mesh = std::sync::Arc::new(TriangleMesh::from_arrays(positions, triangles)?);
    println!("sphere: {} triangles", mesh.len());

    // Rays from z = -3 in a fan across the sphere; the outer two pass beyond its rim (slope 1/sqrt(8)).
    let rays: Vec<Ray> = (0..7)
        .map(|i| {
            let slope = -0.45 + 0.9 * i as f32 / 6.0;
            Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::new(0.0, slope, 1.0).normalize())
        })
        .collect();
    let t_max = vec![f32::INFINITY; rays.len()];

    for &kind in AccelKind::ALL {
        let structure = Structure::build_shared(&AccelConfig::from(kind), mesh.clone())?;
        let mut hits = vec![None; rays.len()];
        structure.intersect_many(&rays, &t_max, &mut hits);
        let stats = structure.stats();
        println!("{kind}: {} nodes, built in {:.2} ms", stats.nodes, stats.build_time.as_secs_f64() * 1e3);
        for (ray, hit) in rays.iter().zip(&hits) {
            match hit {
                Some(h) => println!("  dir {:>6.3}: triangle {:4} at t = {:.5}", ray.dir.y, h.prim, h.t),
                None => println!("  dir {:>6.3}: miss", ray.dir.y),
            }
        }
    }
    Ok(())
}
