//! The path tracer against answers known without it: a white furnace (a sphere inside a uniform white
//! environment gives back the environment's radiance times its albedo, for every sampling option), and
//! Monte Carlo convergence (the variance of a pixel's mean over seeds falls as 1/N; the stratified
//! sampler keeps the mean and lowers that variance).

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::film::Film;
use arbor::light::environment::EnvMap;
use arbor::math::Color;
use arbor::render::{render, RenderOptions};
use arbor::renderer::{PathOptions, Renderer, Roulette};
use arbor::sampler::SamplerKind;
use arbor::scene::{parse_desc, Scene};

/// A sphere of diffuse reflectance `kd` (no BRDF given: the path tracer's normalized Blinn-Phong, with
/// no specular part), seen by a 16x16 camera, with `lights` and `extra` objects.
fn scene_xml(kd: f32, lights: &str, extra: &str) -> String {
    format!(
        r#"<Scene><MaxRecursionDepth>4</MaxRecursionDepth><BackgroundColor>0 0 0</BackgroundColor>
        <Cameras><Camera id="1"><Position>0 0 5</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up>
        <NearPlane>-0.4 0.4 -0.4 0.4</NearPlane><NearDistance>2</NearDistance>
        <ImageResolution>16 16</ImageResolution><ImageName>a.exr</ImageName></Camera></Cameras>
        <Lights>{lights}</Lights>
        <Materials><Material id="1"><AmbientReflectance>0 0 0</AmbientReflectance>
        <DiffuseReflectance>{kd} {kd} {kd}</DiffuseReflectance><SpecularReflectance>0 0 0</SpecularReflectance>
        </Material></Materials>
        <VertexData>0 0 0  -3 -1.2 -3  3 -1.2 -3  3 -1.2 3  -3 -1.2 3</VertexData>
        <Objects><Sphere id="1"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere>{extra}</Objects>
        </Scene>"#
    )
}

fn build(text: &str, environment: Option<EnvMap>) -> Scene {
    let desc = parse_desc(text, Path::new("t.xml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    Scene::build(desc, &AccelConfig::default(), environment).unwrap()
}

fn path(scene: &Scene, options: PathOptions, spp: u32, seed: u64) -> Film {
    let opts =
        RenderOptions { renderer: Some(Renderer::PathTracing(options)), spp: Some(spp), seed, ..Default::default() };
    render(scene, 0, &opts, &|_, _| {}).unwrap().0
}

fn white_environment() -> EnvMap {
    EnvMap::from_film_latlong(Film { width: 8, height: 4, pixels: vec![Color::ONE; 32] })
}

fn mean(f: &Film) -> f32 {
    f.pixels.iter().map(|c| c.x + c.y + c.z).sum::<f32>() / (3 * f.pixels.len()) as f32
}

/// Every option combination but MIS (which needs a light to weigh against), with the unbiased roulette.
fn option_sets() -> Vec<PathOptions> {
    let mut out = Vec::new();
    for bits in 0..8u32 {
        out.push(PathOptions {
            importance_sampling: bits & 1 != 0,
            next_event: bits & 2 != 0,
            roulette: if bits & 4 != 0 { Roulette::Unbiased } else { Roulette::Off },
            mis: false,
            split_refraction: false,
        });
    }
    out
}

#[test]
fn path_white_furnace_gives_back_the_environment_times_the_albedo() {
    for kd in [1.0, 0.5] {
        let scene = build(&scene_xml(kd, "", ""), Some(white_environment()));
        for options in option_sets() {
            let film = path(&scene, options, 64, 1);
            // Light leaves a convex sphere after one bounce: kd times the environment's 1 where the sphere
            // is, 1 around it. The centre 6x6 pixels see only the sphere.
            let centre: Vec<Color> =
                (5..11).flat_map(|y| (5..11).map(move |x| (x, y))).map(|(x, y)| film.pixels[y * 16 + x]).collect();
            let m = centre.iter().map(|c| c.x).sum::<f32>() / centre.len() as f32;
            // Exact but for Russian roulette's and uniform sampling's noise (about 0.01 here).
            let exact = options.importance_sampling && options.roulette == Roulette::Off;
            let tol = if exact { 1e-3 } else { 0.04 };
            assert!((m - kd).abs() < tol, "{options:?}, kd {kd}: centre mean {m}");
            if exact {
                // Cosine sampling of a Lambertian surface makes every sample worth exactly kd.
                assert!(centre.iter().all(|c| (c.x - kd).abs() < 1e-3), "{options:?}: {centre:?}");
            }
            assert!((film.pixels[0].x - 1.0).abs() < 1e-6, "the corner sees the environment");
        }
    }
}

#[test]
fn path_white_furnace_of_a_mirror_with_a_diffuse_colour_gives_back_both_parts() {
    // A mirror of reflectance 0.3 with a diffuse colour of 0.5 reflects 0.8 of a uniform environment: the
    // bounce follows the diffuse part or the mirror in proportion to their weights, so with cosine
    // sampling every sample is worth exactly 0.8; dropping either part gives 0.3 or 0.5.
    let xml = scene_xml(0.5, "", "").replace(
        r#"<Material id="1">"#,
        r#"<Material id="1" type="mirror"><MirrorReflectance>0.3 0.3 0.3</MirrorReflectance>"#,
    );
    let scene = build(&xml, Some(white_environment()));
    for options in option_sets() {
        let film = path(&scene, options, 64, 1);
        let px = &film.pixels;
        let centre: Vec<f32> = (5..11).flat_map(|y| (5..11).map(move |x| px[y * 16 + x].x)).collect();
        let m = centre.iter().sum::<f32>() / centre.len() as f32;
        let exact = options.importance_sampling && options.roulette == Roulette::Off;
        let tol = if exact { 1e-3 } else { 0.04 };
        assert!((m - 0.8).abs() < tol, "{options:?}: centre mean {m}");
        if exact {
            assert!(centre.iter().all(|c| (c - 0.8).abs() < 1e-3), "{options:?}: {centre:?}");
        }
    }
}

#[test]
fn path_split_at_glass_keeps_the_mean_and_takes_the_lobe_choice_out_of_the_noise() {
    // An absorbing glass sphere in a white furnace: what comes back is the Fresnel-weighted mix of
    // reflection and light that crossed the glass, absorbed by its path length inside. Picking one lobe
    // per vertex and following both (the course's split) are both unbiased: the same mean. Splitting
    // takes the lobe choice out of the noise: a sample then varies only with where it lands in its pixel.
    let xml = scene_xml(0.0, "", "").replace(
        r#"<Material id="1">"#,
        r#"<Material id="1" type="dielectric"><AbsorptionCoefficient>0.7 0.7 0.7</AbsorptionCoefficient>
        <RefractionIndex>1.5</RefractionIndex>"#,
    );
    let scene = build(&xml, Some(white_environment()));
    let centre =
        |f: &Film| -> Vec<f32> { (5..11).flat_map(|y| (5..11).map(move |x| f.pixels[y * 16 + x].x)).collect() };
    let run = |split_refraction: bool, seed: u64| {
        centre(&path(&scene, PathOptions { split_refraction, ..PathOptions::default() }, 64, seed))
    };
    let (split, split2, pick, pick2) = (run(true, 1), run(true, 2), run(false, 1), run(false, 2));
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    let seed_to_seed = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>() / a.len() as f32;
    // Two seeds of the lobe choice differ by about 0.024 per pixel here (splitting: 3e-5), so the means
    // of the 36 pixels by about 0.004; a branch weighted 1.5 times puts the split at 0.60 against 0.28.
    let (ms, mp) = (mean(&split), (mean(&pick) + mean(&pick2)) / 2.0);
    assert!((ms - mp).abs() < 0.01 && ms > 0.2 && ms < 0.9, "split {ms}, picked {mp}");
    let (noise_split, noise_pick) = (seed_to_seed(&split, &split2), seed_to_seed(&pick, &pick2));
    assert!(noise_split < 0.25 * noise_pick, "seed to seed: split {noise_split}, picked {noise_pick}");
}

#[test]
fn path_variance_of_a_pixel_mean_falls_as_one_over_the_samples() {
    // A point light over the sphere on a floor: direct light by next event estimation, indirect light by
    // uniform bounces, so each sample is noisy.
    let light = r#"<PointLight id="1"><Position>1 3 2</Position><Intensity>10000 10000 10000</Intensity></PointLight>"#;
    let floor = r#"<Mesh id="2"><Material>1</Material><Faces>2 4 3  2 5 4</Faces></Mesh>"#;
    let scene = build(&scene_xml(0.8, light, floor), None);
    let options = PathOptions { next_event: true, ..Default::default() };
    let variance = |spp: u32| {
        let means: Vec<f32> = (1..=12).map(|seed| mean(&path(&scene, options, spp, seed))).collect();
        let mu = means.iter().sum::<f32>() / means.len() as f32;
        (mu, means.iter().map(|m| (m - mu).powi(2)).sum::<f32>() / (means.len() - 1) as f32)
    };
    let (mu4, v4) = variance(4);
    let (mu64, v64) = variance(64);
    assert!(v64 > 0.0 && mu64 > 0.01, "the image has light and noise: {mu64} {v64}");
    // Sixteen times the samples: a sixteenth of the variance, within a factor of 3 either way for 12 seeds.
    let ratio = v4 / v64;
    assert!((16.0 / 3.0..48.0).contains(&ratio), "variance ratio {ratio} (v4 {v4}, v64 {v64})");
    // And the means agree within their noise.
    assert!((mu4 - mu64).abs() < 4.0 * (v4 / 12.0).sqrt(), "{mu4} vs {mu64}");
}

#[test]
fn path_stratified_and_sobol_samplers_keep_the_mean_and_lower_the_noise() {
    // Two scenes where one kind of sample is the only random number of a vertex: the scene of the test
    // above with uniform bounces (the point light needs no sample), and a square area light with no
    // bounce at all (its light samples, drawn at every vertex, are all the noise).
    let floor = r#"<Mesh id="2"><Material>1</Material><Faces>2 4 3  2 5 4</Faces></Mesh>"#;
    let point = r#"<PointLight id="1"><Position>1 3 2</Position><Intensity>10000 10000 10000</Intensity></PointLight>"#;
    let area = r#"<AreaLight id="1"><Position>1 3 2</Position><Normal>0 -1 0</Normal><Size>2</Size>
        <Radiance>1000 1000 1000</Radiance></AreaLight>"#;
    let direct_only = |xml: String| xml.replace("<MaxRecursionDepth>4<", "<MaxRecursionDepth>0<");
    // Two emitters of different power, one chosen per vertex: the choice is the noise.
    let emitters = r#"<LightSphere id="1"><Material>1</Material><Center>6</Center><Radius>0.3</Radius>
        <Radiance>3000 3000 3000</Radiance></LightSphere><LightSphere id="2"><Material>1</Material>
        <Center>7</Center><Radius>0.3</Radius><Radiance>1000 1000 1000</Radiance></LightSphere>"#;
    let two = direct_only(scene_xml(0.8, "", &format!("{floor}{emitters}")))
        .replace("</VertexData>", " -2.5 1.5 1  2.5 1.5 1</VertexData>");
    let cases = [
        ("bounces", scene_xml(0.8, point, floor)),
        ("area light", direct_only(scene_xml(0.8, area, floor))),
        ("two emitters", two),
    ];
    for (what, xml) in cases {
        let scene = build(&xml, None);
        let renderer = Some(Renderer::PathTracing(PathOptions { next_event: true, ..Default::default() }));
        // Per pixel, the variance of its value over seeds, averaged over the image; and the image's mean.
        let noise = |sampler: SamplerKind| {
            let films: Vec<Film> = (1..=8)
                .map(|seed| {
                    let opts = RenderOptions { renderer, spp: Some(16), seed, sampler, ..Default::default() };
                    render(&scene, 0, &opts, &|_, _| {}).unwrap().0
                })
                .collect();
            let var = pixel_variance(&films, |c| c.x + c.y + c.z);
            (films.iter().map(mean).sum::<f32>() / films.len() as f32, var)
        };
        let (mean_i, var_i) = noise(SamplerKind::Independent);
        let (mean_s, var_s) = noise(SamplerKind::Stratified);
        let (mean_o, var_o) = noise(SamplerKind::Sobol);
        assert!(var_i > 0.0 && mean_i > 0.01, "{what}: the image has light and noise: {mean_i} {var_i}");
        assert!(var_s < 0.8 * var_i, "{what}: stratified variance {var_s} against independent {var_i}");
        assert!((mean_s - mean_i).abs() < 0.02 * mean_i, "{what}: means {mean_s} and {mean_i}");
        // Measured: 0.74x, 0.70x and 0.98x the stratified sampler's variance.
        assert!(var_o < 0.8 * var_i, "{what}: sobol variance {var_o} against independent {var_i}");
        assert!((mean_o - mean_i).abs() < 0.02 * mean_i, "{what}: means {mean_o} and {mean_i}");
    }
}

/// A closed 2x2x2 box seen from its centre looking down at its floor (16x16 pixels, all floor): the five
/// other faces are one `LightMesh` of radiance `le` facing inwards with diffuse reflectance `walls`, the
/// floor reflects `floor`, and glows with the walls if `floor` equals `walls`; no other light.
fn glowing_box(floor: &str, walls: &str, le: f32, depth: u32) -> Scene {
    let (floor_faces, glowing_floor) = if floor == walls { ("", "1 4 3  1 3 2") } else { ("1 4 3  1 3 2", "") };
    let xml = format!(
        r#"<Scene><MaxRecursionDepth>{depth}</MaxRecursionDepth><BackgroundColor>0 0 0</BackgroundColor>
        <Cameras><Camera id="1"><Position>0 0 0</Position><Gaze>0 -1 0</Gaze><Up>0 0 -1</Up>
        <NearPlane>-0.4 0.4 -0.4 0.4</NearPlane><NearDistance>1</NearDistance>
        <ImageResolution>16 16</ImageResolution><ImageName>a.exr</ImageName></Camera></Cameras>
        <Materials><Material id="1"><AmbientReflectance>0 0 0</AmbientReflectance>
        <DiffuseReflectance>{floor}</DiffuseReflectance><SpecularReflectance>0 0 0</SpecularReflectance></Material>
        <Material id="2"><AmbientReflectance>0 0 0</AmbientReflectance><DiffuseReflectance>{walls}</DiffuseReflectance>
        <SpecularReflectance>0 0 0</SpecularReflectance></Material></Materials>
        <VertexData>-1 -1 -1  1 -1 -1  1 -1 1  -1 -1 1  -1 1 -1  1 1 -1  1 1 1  -1 1 1</VertexData>
        <Objects><Mesh id="1"><Material>1</Material><Faces>{floor_faces}</Faces></Mesh>
        <LightMesh id="1"><Material>2</Material><Radiance>{le} {le} {le}</Radiance>
        <Faces>{glowing_floor} 5 6 7  5 7 8  1 5 8  1 8 4  2 3 7  2 7 6  1 2 6  1 6 5  4 8 7  4 7 3</Faces>
        </LightMesh></Objects>
        </Scene>"#
    );
    build(&xml, None)
}

/// The mean radiance of each channel over the image (the film holds it times the radiance scale).
fn channel_means(scene: &Scene, f: &Film) -> [f32; 3] {
    let n = f.pixels.len() as f32;
    [0, 1, 2].map(|c| f.pixels.iter().map(|p| p.to_array()[c]).sum::<f32>() / n / scene.radiance_scale)
}

#[test]
fn path_course_roulette_expects_two_minus_q_times_each_vertex_light() {
    // One bounce from the floor (reflectance kd, BRDF kd/π) always meets the walls' light Le, and the walls
    // reflect nothing. The course's roulette: the floor (vertex 0, throughput t = 1) survives surely;
    // the wall (vertex 1, t = kd/π) with q = max(kd)/π, keeping its emission Le when killed and returning
    // Le/q when it survives: on average (2 - q) Le. So the pixel's expectation is kd (2 - q) Le, where the
    // unbiased answer is kd Le. With next event estimation the floor's own light sample is its light
    // (vertex 0, q = 1: kd Le), the wall's emission met by the bounce is not counted, and the walls have
    // no BRDF to sample light with: the course's roulette is then unbiased, kd Le.
    let kd = [0.8f32, 0.4, 0.2];
    let le = 10.0;
    let scene = glowing_box("0.8 0.4 0.2", "0 0 0", le, 3);
    let q = 0.8 / std::f32::consts::PI;
    for importance_sampling in [true, false] {
        for next_event in [false, true] {
            let options =
                PathOptions { importance_sampling, next_event, roulette: Roulette::Course, ..PathOptions::default() };
            let got = channel_means(&scene, &path(&scene, options, 64, 1));
            let gain = if next_event { 1.0 } else { 2.0 - q };
            for c in 0..3 {
                let want = kd[c] * gain * le;
                assert!((got[c] / want - 1.0).abs() < 0.02, "{options:?}: channel {c} {} against {want}", got[c]);
            }
        }
    }
    // The unbiased roulette and no roulette give kd Le.
    for roulette in [Roulette::Unbiased, Roulette::Off] {
        let options = PathOptions { importance_sampling: true, roulette, ..PathOptions::default() };
        let got = channel_means(&scene, &path(&scene, options, 64, 1));
        assert!((0..3).all(|c| (got[c] / (kd[c] * le) - 1.0).abs() < 0.02), "{roulette:?}: {got:?}");
    }
}

#[test]
fn path_unbiased_roulette_in_a_glowing_furnace_sums_every_bounce() {
    // Every face of the box glows Le and reflects kd: radiance Le (1 + kd + kd² + ...) = Le / (1 - kd).
    // The unbiased roulette has no depth limit (but its cap, where kd^256 is nothing): it converges to
    // that; without a roulette the path stops after MaxRecursionDepth D bounces, Le (1 - kd^(D+1)) / (1 - kd),
    // exactly so in each sample with cosine sampling (each bounce weighs exactly kd).
    let (kd, le, depth) = (0.5f32, 2.0, 3);
    let scene = glowing_box("0.5 0.5 0.5", "0.5 0.5 0.5", le, depth);
    for importance_sampling in [true, false] {
        for next_event in [false, true] {
            let options =
                PathOptions { importance_sampling, next_event, roulette: Roulette::Unbiased, ..PathOptions::default() };
            let got = channel_means(&scene, &path(&scene, options, 64, 1));
            let want = le / (1.0 - kd);
            assert!(got.iter().all(|g| (g / want - 1.0).abs() < 0.02), "{options:?}: {got:?} against {want}");
        }
    }
    // (A ray now and then slips out through the box's edges: the image mean, not every pixel.)
    let options = PathOptions { importance_sampling: true, ..PathOptions::default() };
    let got = channel_means(&scene, &path(&scene, options, 16, 1));
    let want = le * (1.0 - kd.powi(depth as i32 + 1)) / (1.0 - kd);
    assert!(got.iter().all(|g| (g / want - 1.0).abs() < 1e-3), "{got:?} against {want}");
}

#[test]
fn path_mis_weighs_the_last_vertexs_light_samples_against_its_traced_bounce() {
    // In the glowing box (every face glows Le and reflects kd), next event estimation counts the camera
    // hit's emission and one light sample at each of the D + 1 vertices: Le (1 - kd^(D+2)) / (1 - kd).
    // MIS weighs each light sample against the bounce that could meet the same light, the last vertex's
    // too, whose bounce is traced for that light alone: weighed against an untraced bounce, the last
    // vertex's light went missing (at D = 0 a sixth of the image); counted in full, its light samples
    // kept their noise near the walls' edges, where MIS takes the bounce's instead.
    let (kd, le) = (0.5f32, 2.0);
    for depth in [0, 1] {
        let scene = glowing_box("0.5 0.5 0.5", "0.5 0.5 0.5", le, depth);
        let want = le * (1.0 - kd.powi(depth as i32 + 2)) / (1.0 - kd);
        for importance_sampling in [true, false] {
            let mut variance = [0.0; 2];
            for (k, mis) in [false, true].into_iter().enumerate() {
                let options = PathOptions { importance_sampling, next_event: true, mis, ..PathOptions::default() };
                let films: Vec<Film> = (1..=8).map(|seed| path(&scene, options, 8, seed)).collect();
                let got = channel_means(&scene, &films[0]);
                assert!(
                    got.iter().all(|g| (g / want - 1.0).abs() < 0.02),
                    "D {depth}, {options:?}: {got:?} against {want}"
                );
                variance[k] = pixel_variance(&films, |c| c.x);
            }
            let ratio = variance[1] / variance[0];
            assert!(
                ratio < 0.8,
                "D {depth}, importance {importance_sampling}: MIS's variance {ratio} of the light samples'"
            );
        }
    }
}

/// The variance over the films (renders of one scene with different seeds) of each pixel's `value`,
/// averaged over the pixels.
fn pixel_variance(films: &[Film], value: impl Fn(&Color) -> f32) -> f32 {
    let n = films.len() as f32;
    let pixels = films[0].pixels.len();
    (0..pixels)
        .map(|i| {
            let mean = films.iter().map(|f| value(&f.pixels[i])).sum::<f32>() / n;
            films.iter().map(|f| (value(&f.pixels[i]) - mean).powi(2)).sum::<f32>() / (n - 1.0)
        })
        .sum::<f32>()
        / pixels as f32
}

#[test]
fn path_wavefront_gives_each_sample_the_one_path_loops_radiance_bit_for_bit() {
    // The render steps a batch's paths together and traces their shadow and bounce rays in batches; a
    // live view's inspector traces one sample alone. Both must give every sample the same radiance, to
    // the bit, under every option: shadow-ray light summed in the same order, the course's roulette
    // weighing a vertex's light only once its shadow rays are traced, branches of a split path after it.
    // The scene has every kind of light a path meets or samples: a glowing box (emissive geometry),
    // a point light, a glass sphere (split), a mirror with a diffuse colour (the mixture).
    use arbor::integrator::{Integrator, RayLog};
    use arbor::sampler::{SampleStream, Strata};
    let xml = r#"<Scene><MaxRecursionDepth>5</MaxRecursionDepth><BackgroundColor>0 0 0</BackgroundColor>
        <Cameras><Camera id="1"><Position>0 0 0.9</Position><Gaze>0 -0.5 -1</Gaze><Up>0 1 0</Up>
        <NearPlane>-0.6 0.6 -0.6 0.6</NearPlane><NearDistance>1</NearDistance>
        <ImageResolution>12 12</ImageResolution><ImageName>a.exr</ImageName></Camera></Cameras>
        <Lights><PointLight id="1"><Position>0.3 0.8 0.2</Position><Intensity>0.6 0.5 0.4</Intensity></PointLight></Lights>
        <Materials><Material id="1"><AmbientReflectance>0 0 0</AmbientReflectance>
        <DiffuseReflectance>0.7 0.5 0.3</DiffuseReflectance><SpecularReflectance>0 0 0</SpecularReflectance></Material>
        <Material id="2"><AmbientReflectance>0 0 0</AmbientReflectance><DiffuseReflectance>0.4 0.6 0.5</DiffuseReflectance>
        <SpecularReflectance>0 0 0</SpecularReflectance></Material>
        <Material id="3" type="dielectric"><AmbientReflectance>0 0 0</AmbientReflectance>
        <DiffuseReflectance>0 0 0</DiffuseReflectance><SpecularReflectance>0 0 0</SpecularReflectance><AbsorptionCoefficient>0.3 0.2 0.1</AbsorptionCoefficient>
        <RefractionIndex>1.5</RefractionIndex></Material>
        <Material id="4" type="mirror"><AmbientReflectance>0 0 0</AmbientReflectance><DiffuseReflectance>0.3 0.3 0.3</DiffuseReflectance>
        <SpecularReflectance>0 0 0</SpecularReflectance><MirrorReflectance>0.5 0.5 0.5</MirrorReflectance></Material></Materials>
        <VertexData>-1 -1 -1  1 -1 -1  1 -1 1  -1 -1 1  -1 1 -1  1 1 -1  1 1 1  -1 1 1  -0.4 -0.6 -0.3  0.4 -0.6 -0.3</VertexData>
        <Objects><Mesh id="1"><Material>1</Material><Faces>1 4 3  1 3 2</Faces></Mesh>
        <LightMesh id="1"><Material>2</Material><Radiance>0.8 0.8 0.8</Radiance>
        <Faces>5 6 7  5 7 8  1 5 8  1 8 4  2 3 7  2 7 6  1 2 6  1 6 5  4 8 7  4 7 3</Faces></LightMesh>
        <Sphere id="1"><Material>3</Material><Center>9</Center><Radius>0.35</Radius></Sphere>
        <Sphere id="2"><Material>4</Material><Center>10</Center><Radius>0.3</Radius></Sphere></Objects>
        </Scene>"#;
    let scene = build(xml, None);
    let cam = &scene.cameras[0];
    let (spp, seed) = (3, 7);
    let strata = Strata::new(spp);
    let mut options = Vec::new();
    for bits in 0..48u32 {
        let roulette = [Roulette::Off, Roulette::Course, Roulette::Unbiased][(bits / 16) as usize];
        let (next_event, mis) = (bits & 2 != 0, bits & 4 != 0);
        if mis && !next_event {
            continue;
        }
        let (importance_sampling, split_refraction) = (bits & 1 != 0, bits & 8 != 0);
        options.push(PathOptions { importance_sampling, next_event, roulette, mis, split_refraction });
    }
    for sampler in [SamplerKind::Stratified, SamplerKind::Independent, SamplerKind::Sobol] {
        for (n, &o) in options.iter().enumerate() {
            let integrator = Integrator::new(&scene, cam, Renderer::PathTracing(o), false);
            let (mut rays, mut streams, mut hits) = (Vec::new(), Vec::new(), Vec::new());
            for (x, y, k) in (0..12).flat_map(|y| (0..12).flat_map(move |x| (0..spp).map(move |k| (x, y, k)))) {
                let mut s = SampleStream::new(sampler, x, y, k, seed, strata);
                let offset = s.pixel_offset(strata, k);
                let ray = integrator.camera_ray(&cam.ray(x, y, offset, s.rng.next_2d()));
                hits.push(scene.geometry.intersect(&ray, f32::INFINITY));
                rays.push(ray);
                streams.push(s);
            }
            let (mut log, mut batch) = (RayLog::default(), Vec::new());
            let alone: Vec<Color> = (0..rays.len())
                .map(|i| {
                    let mut s = streams[i].clone();
                    integrator.li_camera_hit(&rays[i], hits[i], &mut s, &mut log)
                })
                .collect();
            let rays_alone = log.rays;
            // Two batches of different sizes, one after the other on this thread: whatever the
            // wavefront keeps between batches must not carry over.
            let mut log = RayLog::default();
            let cut = 1 + (n * 97) % (rays.len() - 1);
            let (first, second) = streams.split_at_mut(cut);
            let mut part = Vec::new();
            integrator.li_camera_batch(&rays[..cut], &hits[..cut], first, &mut log, &mut part);
            batch.extend_from_slice(&part);
            integrator.li_camera_batch(&rays[cut..], &hits[cut..], second, &mut log, &mut part);
            batch.extend_from_slice(&part);
            let bits = |c: &Color| c.to_array().map(f32::to_bits);
            let differ = alone.iter().zip(&batch).filter(|(a, b)| bits(a) != bits(b)).count();
            assert_eq!(differ, 0, "{sampler:?} {o:?}: {differ} of {} samples differ", rays.len());
            assert_eq!(log.rays, rays_alone, "{sampler:?} {o:?}: rays counted");
            assert!(alone.iter().any(|c| c.max_element() > 0.0), "{o:?}: a black image tests nothing");
        }
    }
}
