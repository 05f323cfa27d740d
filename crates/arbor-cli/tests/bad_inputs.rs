//! The bad-input catalogue: every file of `tests/bad_inputs/` given to the real `arbor` binary, with the
//! exit code and the exact standard error expected. Each scene file is one kind of bad input (truncated
//! files, wrong counts, non-numbers, NaN and infinite coordinates, indices out of range, missing ids and
//! files, self references, unknown elements, empty scenes, zero-size images, resource limits); scenes
//! named `mesh_*` refer to a bad mesh file next to them, in each of the PLY (ASCII and binary), OBJ and
//! OFF formats.
//!
//! Every run must end within 10 s (else it is killed and the row fails), under a 1 GiB address-space
//! limit, without a panic, and must write no image unless it succeeds. Errors exit 3, or 4 when the file
//! named on the command line cannot be read (a mesh or map the scene names is the scene's fault: 3).
//! Unknown elements and unused properties are warnings (`warning: file:line:col: ...`) and the render
//! succeeds. An empty scene: no camera is an error, no objects renders the background.
//!
//! The runs happen in the catalogue folder, so messages show paths relative to it, as a user sees them.
//! To add a row, add the file and its expected message.
//!
//! Hostile images (decompression bombs, headers claiming huge images, NaN texels) are written by the test
//! itself ([`hostile_images`]) and run the same way, each with an older image in its output folder that
//! must come out unchanged.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[path = "hostile_images/mod.rs"]
mod hostile_images;

/// One run: the arguments after `arbor` (`OUT` at the start of one stands for the output folder), the exit
/// code, stderr.
struct Row {
    args: Vec<&'static str>,
    code: i32,
    stderr: String,
}

/// `arbor render SCENE -o OUT`.
fn render(scene: &'static str, code: i32, stderr: impl Into<String>) -> Row {
    Row { args: vec!["render", scene, "-o", "OUT"], code, stderr: stderr.into() }
}

/// Any other command line.
fn cmd(args: &[&'static str], code: i32, stderr: impl Into<String>) -> Row {
    Row { args: args.to_vec(), code, stderr: stderr.into() }
}

#[rustfmt::skip]
fn catalogue() -> Vec<Row> {
    vec![
    // Truncated files.
    render("truncated.xml", 3, "error: truncated.xml:18:19: XML syntax error: unexpected end of stream\n"),
    render("truncated.json", 3, "error: truncated.json:7: JSON syntax error: EOF while parsing a value\n"),
    render("empty_file.xml", 3, "error: empty_file.xml:1:1: XML syntax error: the document does not have a root node\n"),
    render("mesh_truncated_ascii.xml", 3, "error: truncated_ascii.ply:3: element `vertex` claims 3 entries but only 2 lines are left for it\n"),
    render("mesh_truncated_binary.xml", 3, "error: truncated_binary.ply: byte 206: unexpected end of file in face 0 of 1 (needs 12 more bytes, 4 left)\n"),
    render("mesh_truncated_off.xml", 3, "error: truncated.off:2: header claims 3 vertices and 1 faces but only 2 lines follow\n"),
    render("mesh_truncated_obj.xml", 3, "error: truncated.obj:4: face has 2 vertices (a face needs at least 3)\n"),
    render("mesh_empty_ply.xml", 3, "error: empty.ply:1: not a PLY file (the first line must be `ply`)\n"),
    render("mesh_empty_off.xml", 3, "error: mesh_empty_off.xml:29:9: Mesh 1: mesh file 'empty.off': empty file (expected `OFF`)\n"),
    render("mesh_no_faces_obj.xml", 3, "error: mesh_no_faces_obj.xml:29:9: Mesh 1: mesh file 'no_faces.obj' holds no triangles\n"),
    // Headers that claim more elements than the file holds: refused before allocating.
    render("mesh_huge_count_ply.xml", 3, "error: huge_count.ply:3: element `vertex` claims 4000000000 entries but only 1 lines are left for it\n"),
    render("mesh_huge_count_binary.xml", 3, "error: huge_count_binary.ply:3: element `vertex` claims 1000000000 entries (at least 12000000000 bytes) but only 12 bytes are left for it\n"),
    render("mesh_huge_count_off.xml", 3, "error: huge_count.off:2: header claims 3000000000 vertices and 2000000000 faces but only 1 lines follow\n"),
    // Wrong counts.
    render("faces_not_triples.xml", 3, "error: faces_not_triples.xml:29:44: <Faces>: expected vertex id triples, found 4 ids\n"),
    render("vertexdata_not_triples.xml", 3, "error: vertexdata_not_triples.xml:23:5: <VertexData>: expected x y z triples, found 4 numbers\n"),
    render("resolution_one_number.xml", 3, "error: resolution_one_number.xml:9:13: <ImageResolution>: expected two positive integers\n"),
    render("position_two_numbers.json", 3, "error: position_two_numbers.json:6:9: <Position>: expected 3 numbers, found 2\n"),
    render("nyu_color_two_numbers.json", 3, "error: nyu_color_two_numbers.json:5:29: \"Color\": expected an array of 3 numbers\n"),
    // Header counts that disagree with the data: the element named at its header line.
    render("mesh_vertex_count_high_ply.xml", 3, "error: vertex_count_too_high.ply:3: element `vertex` claims 4 entries but the data has 3 (then a line of another shape)\n"),
    render("mesh_vertex_count_low_ply.xml", 3, "error: vertex_count_too_low.ply:3: element `vertex` claims 2 entries but the data has 3 before the next element\n"),
    render("mesh_vertex_count_binary_ply.xml", 3, "error: vertex_count_binary.ply:3: element `vertex` claims 4 entries but the data holds 3 (then the elements after it fill the file exactly)\n"),
    // Non-numbers.
    render("position_not_a_number.xml", 3, "error: position_not_a_number.xml:4:13: <Position>: malformed number 'zero'\n"),
    render("resolution_not_integer.xml", 3, "error: resolution_not_integer.xml:9:13: <ImageResolution>: malformed integer '8.5'\n"),
    render("huge_depth_number.xml", 3, "error: huge_depth_number.xml:2:5: <MaxRecursionDepth>: malformed integer '99999999999'\n"),
    render("nyu_not_a_number.json", 3, "error: nyu_not_a_number.json:2:60: \"FieldOfView\": expected a number\n"),
    render("mesh_not_a_number_ply.xml", 3, "error: not_a_number.ply:12:5: malformed number `zz`\n"),
    render("mesh_not_a_number_obj.xml", 3, "error: not_a_number.obj:2:5: malformed number `x`\n"),
    render("mesh_not_a_number_off.xml", 3, "error: not_a_number.off:5:3: malformed number `one`\n"),
    // NaN and infinite coordinates.
    render("nan_vertex.xml", 3, "error: nan_vertex.xml:23:5: <VertexData>: non-finite number 'nan'\n"),
    render("inf_radius.xml", 3, "error: inf_radius.xml:29:64: <Radius>: non-finite number 'inf'\n"),
    render("overflow_coordinate.xml", 3, "error: overflow_coordinate.xml:23:5: <VertexData>: out-of-range number '1e39'\n"),
    render("inf_position.json", 3, "error: inf_position.json:6:9: <Position>: non-finite number 'Infinity'\n"),
    render("nyu_overflow.json", 3, "error: nyu_overflow.json:2:60: JSON syntax error: number out of range\n"),
    render("mesh_nan_ply.xml", 3, "error: nan.ply:12: vertex 2: non-finite y (NaN)\n"),
    render("mesh_nan_binary_ply.xml", 3, "error: nan_binary.ply: byte 193: vertex 2: non-finite y (NaN)\n"),
    render("mesh_inf_obj.xml", 3, "error: inf.obj:3:5: non-finite coordinate `inf`\n"),
    render("mesh_inf_off.xml", 3, "error: inf.off:5:5: non-finite coordinate `-inf`\n"),
    // Camera and light values outside their domain (non-finite ones are refused like any number).
    render("num_samples_zero.xml", 3, "error: num_samples_zero.xml:10:13: Camera 1: NumSamples 0 must be at least 1\n"),
    render("num_samples_negative.xml", 3, "error: num_samples_negative.xml:10:13: Camera 1: NumSamples -9 must be at least 1\n"),
    render("num_samples_not_square.xml", 0, "warning: num_samples_not_square.xml:10:13: Camera 1: NumSamples 10 is not a perfect square; using 9 (3x3)\n"),
    render("aperture_negative.xml", 3, "error: aperture_negative.xml:11:13: Camera 1: ApertureSize -0.5 is negative (0 is a pinhole)\n"),
    render("aperture_inf.xml", 3, "error: aperture_inf.xml:11:13: <ApertureSize>: non-finite number 'inf'\n"),
    render("focus_distance_zero.xml", 3, "error: focus_distance_zero.xml:10:13: Camera 1: FocusDistance 0 must be positive\n"),
    render("focus_distance_negative.json", 3, "error: focus_distance_negative.json:13:9: Camera 1: FocusDistance -5 must be positive\n"),
    render("near_distance_zero.xml", 3, "error: near_distance_zero.xml:8:13: Camera 1: NearDistance 0 must be positive\n"),
    render("near_distance_nan.xml", 3, "error: near_distance_nan.xml:8:13: <NearDistance>: non-finite number 'nan'\n"),
    render("near_distance_negative.json", 3, "error: near_distance_negative.json:10:9: Camera 1: NearDistance -2 must be positive\n"),
    render("near_plane_inverted.xml", 3, "error: near_plane_inverted.xml:7:13: Camera 1: NearPlane left 1 must be less than right -1\n"),
    render("near_plane_empty.xml", 3, "error: near_plane_empty.xml:7:13: Camera 1: NearPlane bottom 0.5 must be less than top 0.5\n"),
    render("fovy_180.xml", 3, "error: fovy_180.xml:7:13: Camera 1: FovY 180 must be in (0, 180) degrees\n"),
    render("near_plane_overflow.xml", 3, "error: near_plane_overflow.xml:7:13: Camera 1: the NearPlane window's width overflows to infinity (beyond the range of 32-bit floats)\n"),
    render("fovy_window_overflow.xml", 3, "error: fovy_window_overflow.xml:7:13: Camera 1: the window of NearDistance 1e38 and FovY 170 has a width that overflows to infinity (beyond the range of 32-bit floats)\n"),
    render("area_light_zero_size.xml", 3, "error: area_light_zero_size.xml:18:13: AreaLight 1: Size 0 must be positive\n"),
    // Tone mapping and spot lights (hw5) out of range.
    render("material_degamma_unknown.xml", 3, "error: material_degamma_unknown.xml:19:26: Material 1: degamma must be true or false, not 'yes'\n"),
    render("renderer_unknown_param.xml", 3, "error: renderer_unknown_param.xml:10:45: Camera 1: unknown RendererParams 'Bidirectional' (expected NextEventEstimation, ImportanceSampling, RussianRoulette or MIS)\n"),
    render("tonemap_negative_key.xml", 3, "error: tonemap_negative_key.xml:13:17: Camera 1: TMOOptions key value -0.18 must be positive\n"),
    render("tonemap_burn_out_of_range.xml", 3, "error: tonemap_burn_out_of_range.xml:13:17: Camera 1: TMOOptions burn-out percentage 101 must be in [0, 100]\n"),
    render("tonemap_gamma_zero.xml", 3, "error: tonemap_gamma_zero.xml:15:17: Camera 1: Gamma 0 must be positive\n"),
    render("tonemap_unknown_tmo.xml", 3, "error: tonemap_unknown_tmo.xml:12:17: Camera 1: unknown TMO 'Filmic' (expected Photographic)\n"),
    render("spot_light_zero_coverage.xml", 3, "error: spot_light_zero_coverage.xml:19:13: SpotLight 1: CoverageAngle 0 must be in (0, 360] degrees\n"),
    render("spot_light_falloff_above_coverage.xml", 3, "error: spot_light_falloff_above_coverage.xml:20:13: SpotLight 1: FalloffAngle 20 must be in (0, CoverageAngle 10]\n"),
    render("spot_light_negative_falloff.xml", 3, "error: spot_light_negative_falloff.xml:20:13: SpotLight 1: FalloffAngle -5 must be in (0, CoverageAngle 30]\n"),
    render("area_light_negative_size.xml", 3, "error: area_light_negative_size.xml:18:13: AreaLight 1: Size -1 must be positive\n"),
    render("area_light_zero_normal.xml", 3, "error: area_light_zero_normal.xml:17:13: <Normal>: zero vector\n"),
    render("area_light_nan_radiance.xml", 3, "error: area_light_nan_radiance.xml:19:13: <Radiance>: non-finite number 'nan'\n"),
    render("roughness_negative.xml", 3, "error: roughness_negative.xml:21:13: Material 1: negative roughness -0.2\n"),
    render("background_negative.xml", 3, "error: background_negative.xml:2:5: negative BackgroundColor [-1, 0, 0]\n"),
    render("shadow_epsilon_negative.xml", 3, "error: shadow_epsilon_negative.xml:2:5: negative ShadowRayEpsilon -0.001\n"),
    render("camera_id_duplicate.xml", 3, "error: camera_id_duplicate.xml:12:9: duplicate camera id '1'\n"),
    render("phong_exponent_negative.xml", 3, "error: phong_exponent_negative.xml:21:13: Material 1: negative PhongExponent -5\n"),
    render("refraction_index_zero.xml", 3, "error: refraction_index_zero.xml:21:13: Material 1: RefractionIndex 0 must be positive\n"),
    render("absorption_index_negative.xml", 3, "error: absorption_index_negative.xml:21:96: Material 1: negative AbsorptionIndex -5\n"),
    render("point_light_negative_intensity.xml", 3, "error: point_light_negative_intensity.xml:15:54: PointLight 1: negative Intensity [-900, 900, 900]\n"),
    // BRDFs: a material naming a model that is not there, a model the course does not define, a negative
    // exponent, an option that is not a boolean, Torrance-Sparrow without the index of its Fresnel term.
    render("brdf_missing.xml", 3, "error: brdf_missing.xml:22:26: Material 1: unknown BRDF id '2'\n"),
    render("brdf_unknown_type.xml", 3, "error: brdf_unknown_type.xml:19:9: <BRDFs>: unknown BRDF model <CookTorrance> (expected OriginalPhong, ModifiedPhong, OriginalBlinnPhong, ModifiedBlinnPhong or TorranceSparrow)\n"),
    render("brdf_negative_exponent.xml", 3, "error: brdf_negative_exponent.xml:19:54: BRDF 1: negative exponent -5\n"),
    render("brdf_normalized_not_boolean.xml", 3, "error: brdf_normalized_not_boolean.xml:19:36: attribute normalized: expected true or false, found 'yes'\n"),
    render("brdf_torrance_sparrow_no_index.xml", 3, "error: brdf_torrance_sparrow_no_index.xml:22:26: Material 1: BRDF '1' (TorranceSparrow) needs a <RefractionIndex> for its Fresnel term\n"),
    render("brdf_torrance_sparrow_negative_index.xml", 3, "error: brdf_torrance_sparrow_negative_index.xml:18:56: BRDF 1: RefractiveIndex -1.5 must be positive\n"),
    render("brdf_torrance_sparrow_material_index_negative.xml", 3, "error: brdf_torrance_sparrow_material_index_negative.xml:24:13: Material 1: RefractionIndex -1.5 must be positive\n"),
    // Emissive objects: a negative radiance, a light mesh without triangles, a light without radiance.
    render("light_negative_radiance.xml", 3, "error: light_negative_radiance.xml:29:87: LightSphere 1: negative Radiance [1, -2, 1]\n"),
    render("light_mesh_no_triangles.xml", 3, "error: light_mesh_no_triangles.xml:29:9: LightMesh 1: a light mesh needs at least one triangle\n"),
    render("light_missing_radiance.xml", 3, "error: light_missing_radiance.xml:29:9: <LightMesh>: missing <Radiance>\n"),
    render("motion_blur_nan.xml", 3, "error: motion_blur_nan.xml:29:82: <MotionBlur>: non-finite number 'nan'\n"),
    render("motion_blur_short.xml", 3, "error: motion_blur_short.xml:29:82: <MotionBlur>: expected 3 numbers, found 2\n"),
    render("motion_blur_overflow.xml", 3, "error: motion_blur_overflow.xml:29:9: Sphere 1: its bounds swept by its MotionBlur overflow to infinity (beyond the range of 32-bit floats)\n"),
    render("sphere_bounds_overflow.xml", 3, "error: sphere_bounds_overflow.xml:29:9: Sphere 1: its bounds overflow to infinity (beyond the range of 32-bit floats)\n"),
    // Indices out of range.
    render("face_index_out_of_range.xml", 3, "error: face_index_out_of_range.xml:29:44: Mesh 1: vertex index 9 out of range (VertexData has 3 vertices, numbered from 1)\n"),
    render("face_index_zero.xml", 3, "error: face_index_zero.xml:29:44: Mesh 1: vertex index 0 out of range (VertexData has 3 vertices, numbered from 1)\n"),
    render("vertex_offset_out_of_range.xml", 3, "error: vertex_offset_out_of_range.xml:29:44: Mesh 1: vertex index 1 + vertexOffset -5 = -4 out of range (VertexData has 3 vertices, numbered from 1)\n"),
    render("sphere_center_out_of_range.xml", 3, "error: sphere_center_out_of_range.xml:29:46: Sphere 1: centre vertex 4 out of range (VertexData has 3 vertices, numbered from 1)\n"),
    render("nyu_material_out_of_range.json", 3, "error: nyu_material_out_of_range.json:6:24: \"Material\": Sphere 0: no material 2 (the scene has 0, numbered from 0)\n"),
    render("mesh_index_ply.xml", 3, "error: index_out_of_range.ply:13:7: face 0: vertex index 3 out of range (the file has 3 vertices)\n"),
    render("mesh_index_binary_ply.xml", 3, "error: index_out_of_range_binary.ply: byte 214: face 0: vertex index -1 out of range (the file has 3 vertices)\n"),
    render("mesh_index_obj.xml", 3, "error: index_out_of_range.obj:4:7: vertex index 4 out of range (3 defined so far)\n"),
    render("mesh_index_off.xml", 3, "error: index_out_of_range.off:6:7: face 0: vertex index 3 out of range (the file has 3 vertices)\n"),
    // References to missing ids or files (a file the scene names is the scene's fault: exit 3).
    render("missing_material.xml", 3, "error: missing_material.xml:29:24: Sphere 1: unknown material id '7'\n"),
    render("scaling_overflow.xml", 3, "error: scaling_overflow.xml:29:9: <Scaling>: the transform cannot be inverted: its determinant overflows to infinity (beyond the range of 32-bit floats)\n"),
    render("scaling_tiny.xml", 3, "error: scaling_tiny.xml:29:9: <Scaling>: the transform is too close to singular to invert: its determinant 9.999999e-34 is below 1e-30\n"),
    render("transformations_overflow.xml", 3, "error: transformations_overflow.xml:32:82: <Transformations>: composing 's1 s1' overflows to infinity (an entry of the matrix or of its inverse is beyond the range of 32-bit floats)\n"),
    render("instance_transform_overflow.xml", 3, "error: instance_transform_overflow.xml:33:9: MeshInstance 2: its base's transform followed by its own overflows to infinity (an entry of the matrix or of its inverse is beyond the range of 32-bit floats)\n"),
    render("missing_transformation.xml", 3, "error: missing_transformation.xml:29:82: <Transformations>: unknown transformation 't5'\n"),
    render("missing_base_mesh.xml", 3, "error: missing_base_mesh.xml:30:30: MeshInstance 2: unknown base mesh id '9'\n"),
    render("missing_mesh_file.xml", 3, "error: missing_mesh_file.xml:29:9: Mesh 1: cannot read mesh file 'nowhere.ply': No such file or directory (os error 2)\n"),
    render("nyu_missing_mesh_file.json", 3, "error: nyu_missing_mesh_file.json:6:6: Mesh 0: cannot read mesh file 'nowhere.off': No such file or directory (os error 2)\n"),
    render("env_missing.xml", 3, "error: env_missing.xml:14:43: cannot read environment map 'sky.exr': No such file or directory (os error 2)\n"),
    render("env_truncated.xml", 3, "error: env_truncated.xml:14:43: cannot read environment map 'truncated.png': cannot decode image: unexpected end of file (the file is truncated)\n"),
    render("unknown_mesh_extension.xml", 3, "error: unknown_mesh_extension.xml:29:9: Mesh 1: mesh file 'mesh.stl': unknown mesh file extension `.stl` (supported: .ply, .obj, .off)\n"),
    // Self references. METU has no include; a plyFile may name the scene itself, and a MeshInstance may
    // name itself or another instance (bases must be <Mesh> ids, so no cycle can be written).
    render("ply_is_the_scene.xml", 3, "error: ply_is_the_scene.xml:29:9: Mesh 1: mesh file 'ply_is_the_scene.xml': unknown mesh file extension `.xml` (supported: .ply, .obj, .off)\n"),
    render("ply_is_xml.xml", 3, "error: scene_as.ply:1: not a PLY file (the first line must be `ply`)\n"),
    render("instance_of_itself.xml", 3, "error: instance_of_itself.xml:29:30: MeshInstance 1: base mesh id '1' leads back to this instance\n"),
    render(
        "instance_loop.xml",
        3,
        "error: instance_loop.xml:30:30: MeshInstance 2: base mesh id '1' leads back to this instance\n",
    ),
    render("instance_of_sphere.xml", 3, "error: instance_of_sphere.xml:30:30: MeshInstance 2: unknown base mesh id '1'\n"),
    // Unknown elements and unused properties: warnings, and the render succeeds.
    render("unknown_element.xml", 0, "warning: unknown_element.xml:2:5: <Fog> in <Scene> ignored (unknown or unused here)\n"),
    render("unknown_element.json", 0, "warning: unknown_element.json:3:5: <Fog> in <Scene> ignored (unknown or unused here)\nwarning: unknown_element.json: the scene has no objects: every image shows only the background\n"),
    render("unused_property.xml", 0, "warning: unused_property.xml:3:24: attribute lens of <Camera> ignored (unknown or unused here)\nwarning: unused_property.xml:29:82: <Faces> in <Sphere> ignored (unknown or unused here)\n"),
    render("nyu_unknown_key.json", 0, "warning: nyu_unknown_key.json:6:75: \"Colour\" in an object ignored (unknown)\n"),
    // -q hides progress and summaries, not warnings; -qq and --no-warnings hide warnings too.
    cmd(&["render", "unknown_element.xml", "-q", "-o", "OUT"], 0, "warning: unknown_element.xml:2:5: <Fog> in <Scene> ignored (unknown or unused here)\n"),
    cmd(&["render", "unknown_element.xml", "-qq", "-o", "OUT"], 0, ""),
    cmd(&["render", "unknown_element.xml", "--no-warnings", "-o", "OUT"], 0, ""),
    // A camera whose up is parallel to its gaze.
    render("up_parallel_to_gaze.xml", 0, "warning: up_parallel_to_gaze.xml:3:9: Camera 1: Up [0, 0, 2] is parallel to Gaze [0, 0, -1]: the image's orientation is undefined\n"),
    // Most camera rays meet back faces in an unculled XML render (the form does not say whether it
    // expects culling): a warning naming --cull, unless a flag chose. The 2025 JSON form culls.
    render("back_faces.xml", 0, "warning: back_faces.xml:3:9: Camera 1: 100% of camera rays meet back faces; if the scene expects back-face culling, render with --cull\n"),
    cmd(&["render", "back_faces.xml", "--cull", "-o", "OUT"], 0, ""),
    cmd(&["render", "back_faces.xml", "--no-cull", "-o", "OUT"], 0, ""),
    render("back_faces.json", 0, ""),
    cmd(&["render", "back_faces.json", "--no-cull", "-o", "OUT"], 0, ""),
    // Empty scenes: no camera is an error; no objects renders the background.
    render("no_camera.xml", 3, "error: no_camera.xml: the scene has no camera\n"),
    render("empty_scene.xml", 3, "error: empty_scene.xml: the scene has no camera\n"),
    render("no_objects.xml", 0, "warning: no_objects.xml: the scene has no objects: every image shows only the background\n"),
    // --roulette picks the roulette of cameras that have one: a camera without says so.
    cmd(&["render", "no_objects.xml", "--roulette", "course", "-o", "OUT"], 0, "warning: no_objects.xml: the scene has no objects: every image shows only the background\nwarning: --roulette course: camera 1 has no Russian roulette, its paths end at MaxRecursionDepth (a path-traced camera gets one from RussianRoulette or --path-options roulette)\n"),
    // A path tracer with no light it can take: every object black (the background still shows).
    render("path_tracing_no_light.xml", 0, "warning: path_tracing_no_light.xml:4:9: Camera 1: the path tracer finds no light: the scene has no light, no emitter and no environment map; every object renders black\n"),
    render("path_tracing_point_light_no_nee.xml", 0, "warning: path_tracing_point_light_no_nee.xml:4:9: Camera 1: the path tracer finds no light: without NextEventEstimation it takes no light from point, spot, directional or area lights, and the scene has no emitter or environment map (NextEventEstimation in RendererParams, or --path-options next-event, samples them); every object renders black\n"),
    render("no_light.xml", 0, ""),
    cmd(&["render", "no_light.xml", "--integrator", "path", "-o", "OUT"], 0, "warning: no_light.xml:3:9: Camera 1: the path tracer finds no light: the scene has no light, no emitter and no environment map; every object renders black\n"),
    render("empty_object.json", 3, "error: empty_object.json:1:1: no top-level \"Scene\" object\n"),
    render("not_a_scene.xml", 3, "error: not_a_scene.xml:1:1: root element is <Mesh>, expected <Scene>\n"),
    // Zero-size images.
    render("zero_size.xml", 3, "error: zero_size.xml:9:13: <ImageResolution>: expected two positive integers\n"),
    render("zero_width.json", 3, "error: zero_width.json:11:9: <ImageResolution>: expected two positive integers\n"),
    render("negative_size.xml", 3, "error: negative_size.xml:9:13: <ImageResolution>: expected two positive integers\n"),
    // Resource limits.
    render("huge_image.xml", 3, "error: huge_image.xml:3:9: Camera 1: image 100000x100000 exceeds the limit of 16384x16384 pixels; --no-limits lifts the limits\n"),
    render("huge_samples.xml", 3, "error: huge_samples.xml:3:9: Camera 1: NumSamples 1000000 exceeds the limit of 65536 samples per pixel; --no-limits lifts the limits\n"),
    render("huge_work.xml", 3, "error: huge_work.xml:3:9: Camera 1: 268435456 pixels x 1024 samples = 274877906944 samples, more than the limit of 17179869184; --no-limits lifts the limits\n"),
    render("huge_work_cameras.xml", 3, "error: huge_work_cameras.xml: the scene's 2 cameras ask for 19327352832 samples in all, more than the limit of 17179869184; --no-limits lifts the limits\n"),
    // A glass sphere in a closed box of mirrors at depth 64: ~10^13 rays a sample, never finished before
    // the ray-tree budget; now at most twice the budget a sample, with a warning before and after.
    render("glass_in_mirror_box.xml", 0, "warning: glass_in_mirror_box.xml: a sample's ray tree may hold 3.689e19 rays (recursion depth 64, 2 rays per hit); pruning the branches too weak to change a pixel by 1/16 of a level leaves up to 7.140e9: a sample traces at most 4096, and one that needs more drops its lightest branches, which may show\nwarning: glass_in_mirror_box.xml: Camera 1: 36 of 64 samples needed more than 4096 rays and dropped their lightest branches\n"),
    render("deep_recursion.xml", 3, "error: deep_recursion.xml:2:5: MaxRecursionDepth 100 exceeds the limit of 64; --no-limits lifts the limits\n"),
    // A run of several cameras checks every output name, and reserves every image's memory, before the
    // first render: the first image was written, then the second failed.
    render("image_name_too_long.xml", 3, "error: image_name_too_long.xml:19:13: Camera 2: ImageName 'bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb…bbbbbbbbbbbb.png': a file or folder name in it is 304 bytes long, more than the 255 this file system takes (NAME_MAX)\n"),
    render("memory_second_camera.xml", 4, "error: not enough memory for a 16000x16000 image (23.8 GiB)\n"),
    // Not a scene file.
    render("not_utf8.xml", 3, "error: not_utf8.xml: byte 309: not UTF-8 text\n"),
    render("entity_declared.xml", 3, "error: entity_declared.xml:4:5: entity declarations (<!ENTITY>) are not supported: no scene format uses them\n"),
    render("scene.txt", 3, "error: scene.txt: unknown scene format '.txt' (expected .xml or .json)\n"),
    // Files that cannot be read: I/O errors, exit 4.
    cmd(&["render", "no_such_scene.xml", "-o", "OUT"], 4, "error: no_such_scene.xml: No such file or directory (os error 2)\n"),
    // Limits: --spp on the command line, the flag that lifts them, and the other commands.
    cmd(&["render", "no_objects.xml", "--spp", "100000", "-o", "OUT"], 3, "warning: no_objects.xml: the scene has no objects: every image shows only the background\nerror: --spp 100000 exceeds the limit of 65536 samples per pixel; --no-limits lifts the limits\n"),
    cmd(&["render", "deep_recursion.xml", "--no-limits", "-o", "OUT"], 0, ""),
    // Structure parameters outside their range, or that do not apply: usage errors (exit 2), found
    // before the scene is read.
    cmd(&["render", "no_objects.xml", "--accel-param", "leaf=0", "-o", "OUT"], 2, "error: parameter 'leaf': 0 is outside its range 1..=64\n"),
    cmd(&["render", "no_objects.xml", "--accel-param", "leaf=1000", "-o", "OUT"], 2, "error: parameter 'leaf': 1000 is outside its range 1..=64\n"),
    cmd(&["render", "no_objects.xml", "--accel", "bvh-sah", "--accel-param", "bins=1", "-o", "OUT"], 2, "error: parameter 'bins': 1 is outside its range 2..=32\n"),
    cmd(&["render", "no_objects.xml", "--accel", "octree", "--accel-param", "depth=99", "-o", "OUT"], 2, "error: parameter 'depth': 99 is outside its range 0..=16\n"),
    cmd(&["render", "no_objects.xml", "--accel", "kdtree", "--accel-param", "empty-bonus=5", "-o", "OUT"], 2, "error: parameter 'empty-bonus': 5 is outside its range 0..=1\n"),
    cmd(&["render", "no_objects.xml", "--accel", "kdtree", "--accel-param", "traversal-cost=-5", "-o", "OUT"], 2, "error: parameter 'traversal-cost': -5 is outside its range >= 0\n"),
    cmd(&["render", "no_such_scene.xml", "--accel", "bvh-median", "--accel-param", "leaf=65", "-o", "OUT"], 2, "error: parameter 'leaf': 65 is outside its range 1..=64\n"),
    cmd(&["render", "no_objects.xml", "--accel-param", "leaf=many", "-o", "OUT"], 2, "error: parameter 'leaf': cannot read 'many' (expected 1..=64)\n"),
    cmd(&["render", "no_objects.xml", "--accel-param", "depth=3", "-o", "OUT"], 2, "error: bvh-sah has no parameter 'depth' (it has: leaf, bins, traversal-cost, intersection-cost, leaf-block)\n"),
    cmd(&["render", "no_objects.xml", "--accel", "brute", "--accel-param", "leaf=4", "-o", "OUT"], 2, "error: brute takes no parameters (got 'leaf')\n"),
    cmd(&["render", "no_objects.xml", "--accel-param", "leaf", "-o", "OUT"], 2, "error: 'leaf' is not KEY=VALUE\n"),
    cmd(&["info", "no_objects.xml", "--accel", "bvh-bottom-up", "--accel-param", "radius=0"], 2, "error: parameter 'radius': 0 is outside its range 1..=256\n"),
    cmd(&["info", "no_objects.xml", "--accel", "bvh-bottom-up", "--accel-param", "method=best"], 2, "error: parameter 'method': cannot read 'best' (expected auto|greedy|ploc)\n"),
    cmd(&["bench", "sphere:100", "--accel", "kdtree", "--accel-param", "kdtree:depth=64"], 2, "error: --accel-param 'kdtree:depth=64': parameter 'depth': 64 is outside its range auto or 0..=63\n"),
    cmd(&["bench", "sphere:100", "--accel", "octree", "--accel-param", "kdtree:depth=4"], 2, "error: --accel-param 'kdtree:depth=4': kdtree is not benchmarked (see --accel)\n"),
    cmd(&["bench", "sphere:100", "--accel-param", "depth=4"], 2, "error: --accel-param 'depth=4' is not KIND:KEY=VALUE\n"),
    // Merge: a part that is no partial EXR, or missing.
    cmd(&["merge", "truncated.xml", "-o", "OUT/merged.png"], 3, "error: truncated.xml: not a readable OpenEXR file: invalid: file identifier missing\n"),
    cmd(&["merge", "truncated.xml", "-o", "merged.bmp"], 2, "error: cannot write .bmp images; supported: png, ppm, exr, hdr, jpg, jpeg\n"),
    cmd(&["merge", "no_such_part.exr", "-o", "OUT/merged.png"], 4, "error: no_such_part.exr: No such file or directory (os error 2)\n"),
    // Diff: a truncated or corrupt image is bad input (exit 3) in every format; a missing one is I/O (4).
    cmd(&["diff", "tex.png", "truncated.png"], 3, "error: truncated.png: cannot decode image: unexpected end of file (the file is truncated)\n"),
    cmd(&["diff", "tex.png", "truncated.ppm"], 3, "error: truncated.ppm: cannot decode image: unexpected end of file (the file is truncated)\n"),
    cmd(&["diff", "tex.png", "truncated.jpg"], 3, "error: truncated.jpg: cannot decode image: the JPEG data ends before its end-of-image marker (the file is truncated)\n"),
    cmd(&["diff", "tex.png", "truncated.exr"], 3, "error: truncated.exr: cannot decode image: not a readable OpenEXR file: invalid: reference to missing bytes\n"),
    cmd(&["diff", "tex.png", "no_such_image.png"], 4, "error: no_such_image.png: No such file or directory (os error 2)\n"),
    cmd(&["info", "huge_image.xml"], 3, "error: huge_image.xml:3:9: Camera 1: image 100000x100000 exceeds the limit of 16384x16384 pixels; --no-limits lifts the limits\n"),
    cmd(&["info", "huge_image.xml", "--no-limits"], 0, ""),
    cmd(&["bench", "huge_image.xml", "--runs", "1"], 3, "error: huge_image.xml:3:9: Camera 1: image 100000x100000 exceeds the limit of 16384x16384 pixels; --no-limits lifts the limits\n"),
    // Textures: missing or undecodable images, unknown modes, types and ids, coordinates out of range,
    // divisors and frequencies that are not positive.
    render("texture_coord_out_of_range.xml", 3, "error: texture_coord_out_of_range.xml:38:66: Mesh 1: texture coordinate 3 + textureOffset 1 = 4 out of range (TexCoordData has 3 pairs, numbered from 1)\n"),
    render("texture_coords_empty.xml", 3, "error: texture_coords_empty.xml:34:44: Mesh 1: image texture '1' needs texture coordinates, but TexCoordData has no (u, v) pairs (every point would show the texel at (0, 0))\n"),
    render("texture_checkerboard_scale_zero.xml", 3, "error: texture_checkerboard_scale_zero.xml:28:13: TextureMap 1: Scale 0 must be positive\n"),
    render("texture_image_missing.xml", 3, "error: texture_image_missing.xml:24:17: cannot read texture image 'nothere.png': No such file or directory (os error 2)\n"),
    render("texture_image_unreadable.xml", 3, "error: texture_image_unreadable.xml:24:17: cannot read texture image 'not_an_image.png': cannot decode image: Format error decoding Png: Invalid PNG signature.\n"),
    render("texture_image_truncated_jpg.xml", 3, "error: texture_image_truncated_jpg.xml:24:17: cannot read texture image 'truncated.jpg': cannot decode image: the JPEG data ends before its end-of-image marker (the file is truncated)\n"),
    render("texture_image_truncated_png.xml", 3, "error: texture_image_truncated_png.xml:24:17: cannot read texture image 'truncated.png': cannot decode image: unexpected end of file (the file is truncated)\n"),
    render("texture_noise_scale_negative.xml", 3, "error: texture_noise_scale_negative.xml:24:75: TextureMap 1: NoiseScale -2 must be positive\n"),
    render("texture_normalizer_zero.xml", 3, "error: texture_normalizer_zero.xml:25:94: TextureMap 1: Normalizer 0 must be positive\n"),
    render("texture_unknown_decal.xml", 3, "error: texture_unknown_decal.xml:25:61: TextureMap 1: unknown DecalMode 'replace_everything'\n"),
    render("texture_unknown_id.xml", 3, "error: texture_unknown_id.xml:33:46: Sphere 1: no texture map with id '7'\n"),
    render("texture_unknown_type.xml", 3, "error: texture_unknown_type.xml:25:28: TextureMap 1: unknown type 'marble'\n"),
    // Mesh files given directly: bench takes them, render and info say so.
    cmd(&["render", "huge_count.ply", "-o", "OUT"], 3, "error: huge_count.ply: this is a mesh file, not a scene (.xml or .json); `arbor bench huge_count.ply` takes meshes\n"),
    cmd(&["info", "inf.obj"], 3, "error: inf.obj: this is a mesh file, not a scene (.xml or .json); `arbor bench inf.obj` takes meshes\n"),
    cmd(&["bench", "huge_count.off"], 3, "error: huge_count.off:2: header claims 3000000000 vertices and 2000000000 faces but only 1 lines follow\n"),
    cmd(&["bench", "scene_as.ply"], 3, "error: scene_as.ply:1: not a PLY file (the first line must be `ply`)\n"),
    ]
}

/// What went wrong with one row, if anything: a run that fails must leave the files of `out` (a folder,
/// missing or holding older images) as they were.
fn run(row: &Row, dir: &Path, out: &Path) -> Result<(), String> {
    let before = files(out);
    let args: Vec<String> = row
        .args
        .iter()
        .map(|a| match a.strip_prefix("OUT") {
            Some(rest) => format!("{}{rest}", out.display()),
            None => a.to_string(),
        })
        .collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let err_path = out.with_extension("stderr");
    let err_file = std::fs::File::create(&err_path).unwrap();
    let mut command = limited(&args);
    let mut child = command
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err_file)
        .spawn()
        .expect("arbor runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(10) {
            child.kill().ok();
            child.wait().ok();
            return Err("still running after 10 s: killed".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = without_progress(&std::fs::read_to_string(&err_path).unwrap());
    if stderr.contains("panicked") || status.code() == Some(101) {
        return Err(format!("panicked: {stderr}"));
    }
    let Some(code) = status.code() else {
        return Err(format!("killed by a signal (out of memory?): {status}; stderr: {stderr}"));
    };
    if (code, stderr.as_str()) != (row.code, row.stderr.as_str()) {
        return Err(format!("exit {code}, stderr:\n{stderr}expected exit {}, stderr:\n{}", row.code, row.stderr));
    }
    let after = files(out);
    let written =
        after.iter().filter(|f| !before.contains(f)).count() + before.iter().filter(|f| !after.contains(f)).count();
    if matches!(row.args[0], "render" | "merge") && (code == 0) != (written > 0) {
        return Err(format!("exit {code} but {written} files written, changed or removed"));
    }
    Ok(())
}

/// The files of the folder `dir` with their contents, sorted (none when it is missing).
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.map(|e| e.unwrap().path()).map(|p| (p.clone(), std::fs::read(&p).unwrap())).collect())
        .unwrap_or_default();
    files.sort();
    files
}

/// Standard error without the plain progress lines a render prints when it is not a terminal
/// (`NAME: 50% (32/64 pixels, 0.1 s)`): they carry timings, and the catalogue is about messages.
fn without_progress(stderr: &str) -> String {
    let progress = |l: &str| l.contains("% (") && l.contains(" pixels, ") && l.ends_with(" s)");
    stderr.lines().filter(|l| !progress(l)).map(|l| format!("{l}\n")).collect()
}

/// `arbor args`, limited to 1 GiB of address space where the shell can say so.
fn limited(args: &[&str]) -> Command {
    let exe = env!("CARGO_BIN_EXE_arbor");
    if cfg!(unix) {
        let mut c = Command::new("sh");
        c.arg("-c").arg("ulimit -v 1048576 && exec \"$0\" \"$@\"").arg(exe).args(args);
        c
    } else {
        let mut c = Command::new(exe);
        c.args(args);
        c
    }
}

fn catalogue_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs")
}

#[test]
fn bad_inputs_give_located_errors_and_never_panic() {
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for (i, row) in catalogue().iter().enumerate() {
        let out = tmp.path().join(format!("run{i}"));
        if let Err(e) = run(row, &catalogue_dir(), &out) {
            failures.push(format!("arbor {}: {e}", row.args.join(" ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n\n{}",
        failures.len(),
        catalogue().len(),
        failures.join("\n\n")
    );
}

/// The hostile images of [`hostile_images`], written into a folder of their own, each run with an older
/// image of the name it would write (`out.png`, `merged.png`) in its output folder.
#[test]
fn bad_inputs_hostile_images_are_refused_before_decoding_and_never_abort() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("images");
    std::fs::create_dir(&dir).unwrap();
    hostile_images::write_all(&dir, &catalogue_dir());
    let mut failures = Vec::new();
    let rows = hostile_images::rows();
    for (i, row) in rows.iter().enumerate() {
        let out = tmp.path().join(format!("run{i}"));
        std::fs::create_dir(&out).unwrap();
        for name in ["out.png", "merged.png"] {
            std::fs::write(out.join(name), b"an older image").unwrap();
        }
        if let Err(e) = run(row, &dir, &out) {
            failures.push(format!("arbor {}: {e}", row.args.join(" ")));
        }
    }
    assert!(failures.is_empty(), "{} of {} rows failed:\n\n{}", failures.len(), rows.len(), failures.join("\n\n"));
}

/// Every scene of the catalogue has its row, and every mesh file and image is named by some scene
/// or row, so that no file lies there untested.
#[test]
fn bad_inputs_catalogue_is_complete() {
    let rows = catalogue();
    let named = |name: &str| rows.iter().any(|r| r.args.contains(&name));
    let mut scenes = String::new();
    let mut meshes = Vec::new();
    for entry in std::fs::read_dir(catalogue_dir()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        match Path::new(&name).extension().and_then(|e| e.to_str()) {
            Some("ply" | "obj" | "off" | "png" | "ppm" | "exr" | "jpg") => meshes.push(name),
            _ => {
                assert!(named(&name), "no row for {name}");
                scenes.push_str(&String::from_utf8_lossy(&std::fs::read(catalogue_dir().join(&name)).unwrap()));
            }
        }
    }
    for m in meshes {
        let used = scenes.contains(&format!("\"{m}\"")) || scenes.contains(&format!(">{m}<"));
        assert!(used || named(&m), "no scene or row uses {m}");
    }
}

/// The entity bomb of the third hardening round, generated: 53 KB whose two levels of entities expand
/// to about 12 GB of text (20 KB of text, 255 references to it in one entity, 2,400 references to that
/// in the document), which the XML parser spent minutes on. Refused at its first declaration, within
/// the catalogue's 10 s and 1 GiB.
#[test]
fn bad_inputs_entity_bomb_of_12_gb_is_refused_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    let text = format!(
        "<?xml version=\"1.0\"?>\n<!DOCTYPE Scene [\n  <!ENTITY a \"{}\">\n  <!ENTITY b \"{}\">\n]>\n<Scene>{}</Scene>\n",
        "x".repeat(20_000),
        "&a;".repeat(255),
        "&b;".repeat(2_400)
    );
    assert!(text.len() > 25_000 && text.len() < 54_000, "{} bytes", text.len());
    std::fs::write(tmp.path().join("bomb.xml"), text).unwrap();
    let row = render(
        "bomb.xml",
        3,
        "error: bomb.xml:3:3: entity declarations (<!ENTITY>) are not supported: no scene format uses them\n",
    );
    run(&row, tmp.path(), &tmp.path().join("out")).unwrap();
}
