//! What the `arbor` binary's test files share: running it, reading what it printed, and the scene most
//! of them render (one sphere under a point light and an ambient light) around their own cameras.

// Each test file is its own crate and uses a part of this.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// `arbor ARGS` run in `cwd`, to its end.
pub fn arbor(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_arbor")).args(args).current_dir(cwd).output().expect("arbor runs")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A METU scene of a unit sphere at the origin (material 1, diffuse `1 0.5 0.2`, ambient `1 1 1`,
/// radius written `<Radius>1</Radius>`) under `<AmbientLight>30 30 30` and a point light, seen by
/// `cameras` (`<Camera>` elements).
pub fn sphere_scene(cameras: &str) -> String {
    format!(
        r#"<Scene>
    <Cameras>
{cameras}
    </Cameras>
    <Lights>
        <AmbientLight>30 30 30</AmbientLight>
        <PointLight id="1"><Position>0 3 5</Position><Intensity>900 900 900</Intensity></PointLight>
    </Lights>
    <Materials>
        <Material id="1">
            <AmbientReflectance>1 1 1</AmbientReflectance>
            <DiffuseReflectance>1 0.5 0.2</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
    </Materials>
    <VertexData>0 0 0</VertexData>
    <Objects>
        <Sphere id="1"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere>
    </Objects>
</Scene>
"#
    )
}
