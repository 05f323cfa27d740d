//! The Whitted integrator's ray-tree pruning and budget (`arbor::integrator::TreePlan`): trees within
//! the budget are traced whole, pruning changes no pixel by more than a sixteenth of an 8-bit level, and
//! at any recursion depth a camera sample traces a bounded number of rays.

use arbor::accel::AccelConfig;
use arbor::integrator::{RayLog, TreePlan, Whitted, PRUNED_LEVELS, TREE_BUDGET};
use arbor::math::Vec2;
use arbor::render::{render, RenderOptions};
use arbor::sampler::Rng;
use arbor::scene::{parse_desc, Scene};

/// A glass sphere inside a closed box of mirrors (normals inwards) lit by a point light: every glass hit
/// spawns two rays, and the box never lets a ray escape.
fn mirror_box(depth: u32, mirror: f32, size: u32) -> Scene {
    let faces = "1 2 3  1 3 4  5 7 6  5 8 7  1 6 2  1 5 6  4 3 7  4 7 8  1 4 8  1 8 5  2 6 7  2 7 3";
    let text = format!(
        r#"<Scene>
    <MaxRecursionDepth>{depth}</MaxRecursionDepth>
    <Cameras><Camera id="1"><Position>0 0 0.9</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up>
        <NearPlane>-1 1 -1 1</NearPlane><NearDistance>1</NearDistance>
        <ImageResolution>{size} {size}</ImageResolution><ImageName>box.png</ImageName></Camera></Cameras>
    <Lights><AmbientLight>10 10 10</AmbientLight>
        <PointLight id="1"><Position>0.5 0.5 0.5</Position><Intensity>100 100 100</Intensity></PointLight></Lights>
    <Materials>
        <Material id="1" type="mirror"><AmbientReflectance>0.1 0.1 0.1</AmbientReflectance>
            <DiffuseReflectance>0.1 0.1 0.1</DiffuseReflectance><SpecularReflectance>0 0 0</SpecularReflectance>
            <MirrorReflectance>{mirror} {mirror} {mirror}</MirrorReflectance></Material>
        <Material id="2" type="dielectric"><AmbientReflectance>0 0 0</AmbientReflectance>
            <DiffuseReflectance>0 0 0</DiffuseReflectance><SpecularReflectance>0 0 0</SpecularReflectance>
            <AbsorptionCoefficient>0 0 0</AbsorptionCoefficient><RefractionIndex>1.5</RefractionIndex></Material>
    </Materials>
    <VertexData>-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1  0 0 0</VertexData>
    <Objects>
        <Mesh id="1"><Material>1</Material><Faces>{faces}</Faces></Mesh>
        <Sphere id="1"><Material>2</Material><Center>9</Center><Radius>0.5</Radius></Sphere>
    </Objects>
</Scene>"#
    );
    let desc = parse_desc(&text, std::path::Path::new("box.xml")).unwrap_or_else(|e| panic!("{e}"));
    Scene::build(desc, &AccelConfig::default(), None).unwrap()
}

/// Every pixel's radiance (one sample through its centre) and the rays traced, by `w`.
fn trace(scene: &Scene, w: &Whitted) -> (Vec<[f32; 3]>, u64) {
    let cam = &scene.cameras[0];
    let mut log = RayLog::default();
    let mut out = Vec::new();
    for y in 0..cam.height {
        for x in 0..cam.width {
            let mut rng = Rng::for_sample(x, y, 0, 0);
            let c = w.li_camera(&cam.ray(x, y, Vec2::splat(0.5), Vec2::ZERO), &mut rng, &mut log);
            out.push(c.to_array());
        }
    }
    (out, log.rays)
}

#[test]
fn whitted_pruning_leaves_trees_within_the_budget_whole() {
    // Depth 11, two lobes: 4095 rays, within the budget; depth 12: 8191, beyond it.
    let plan = TreePlan::of(&mirror_box(11, 0.9, 4));
    assert_eq!((plan.full, plan.pruning.is_some(), plan.warning()), (4095.0, false, None));
    let plan = TreePlan::of(&mirror_box(12, 0.9, 4));
    assert!(plan.full > TREE_BUDGET as f64 && plan.pruning.is_some(), "{plan:?}");
}

#[test]
fn whitted_pruning_changes_no_pixel_by_a_sixteenth_of_a_level() {
    // Dim mirrors: weights fall fast, so pruning cuts much of a depth-16 tree.
    let scene = mirror_box(16, 0.3, 24);
    let plan = TreePlan::of(&scene);
    assert!(plan.pruning.is_some() && plan.unbounded.is_none(), "{plan:?}");
    let cam = &scene.cameras[0];
    let (pruned, pruned_rays) = trace(&scene, &Whitted::new(&scene, false).with_camera(cam));
    let (exact, exact_rays) = trace(&scene, &Whitted::new(&scene, false).with_camera(cam).exact());
    assert!(pruned_rays < exact_rays / 2, "pruning cut too little: {pruned_rays} of {exact_rays} rays");
    // One level of the 8-bit image is one unit of radiance in a METU scene (radiance scale 1/255).
    let level = 1.0 / (255.0 * scene.radiance_scale);
    let worst = pruned.iter().zip(&exact).flat_map(|(p, e)| (0..3).map(move |c| e[c] - p[c])).fold(0.0f32, f32::max);
    assert!(worst >= 0.0 && worst <= PRUNED_LEVELS * level, "a pixel lost {worst} of radiance");
}

#[test]
fn whitted_pruning_bounds_the_rays_of_a_sample_at_any_depth() {
    for depth in [64, 1000] {
        let scene = mirror_box(depth, 1.0, 6);
        let plan = TreePlan::of(&scene);
        assert!(plan.warning().is_some_and(|w| w.contains("may hold")), "{plan:?}");
        let (film, stats) = render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
        // Two passes of at most the budget each, plus one shadow ray per light at every hit.
        let per_sample = 2 * TREE_BUDGET as u64 * (1 + scene.lights.len() as u64);
        assert!(stats.rays <= 36 * per_sample, "depth {depth}: {} rays", stats.rays);
        assert!(stats.capped_samples > 0, "depth {depth}: no sample reached the budget");
        // Deterministic: a crop is the same region of the full image.
        let crop = RenderOptions { crop: Some((2, 2, 5, 4)), ..Default::default() };
        let part = render(&scene, 0, &crop, &|_, _| {}).unwrap().0;
        let region: Vec<_> = (2..4).flat_map(|y| (2..5).map(move |x| (x, y))).map(|(x, y)| film.get(x, y)).collect();
        assert_eq!(part.pixels, region, "depth {depth}");
    }
}
