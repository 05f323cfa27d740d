//! The `Textures` of a METU scene (CENG 795 2022 hw4): `Images` (file names by id) and `TextureMap`s
//! of type `image`, `perlin` or `checkerboard`, each with its `DecalMode`; objects name their maps in
//! their own `Textures` element. `TexCoordData` holds the (u, v) pairs of inline meshes.
//!
//! The pre-2022 form (2019 hw4) is read into the same description: a `Texture` names its file in
//! `ImageName` (or `perlin`, `checkerboard`), scales procedures by `ScalingFactor` (Perlin `Appearance`
//! `patch` is the linear conversion, `vein` the absolute value), and with `bumpmap="true"` is also a
//! bump map (`bumpmapMultiplier`); objects name it in `Texture` elements, and `BackgroundTexture` names
//! the background's file.

use std::collections::HashMap;

use super::Reader;
use crate::math::{Color, Vec2};
use crate::scene::desc::{DecalMode, ImageDesc, Interpolation, NoiseConversion, TextureDesc, TextureSource};
use crate::scene::readers::tree::Node;
use crate::{Error, Result};

impl Reader<'_> {
    /// Every image and texture map of a `Textures` element.
    pub(super) fn textures(&mut self, t: &Node) -> Result<()> {
        t.mark_used();
        let mut images: HashMap<String, usize> = HashMap::new();
        for list in t.all("Images") {
            list.mark_used();
            for img in list.all("Image") {
                img.mark_used();
                let id = img.attr("id").ok_or_else(|| self.err(img, "<Image>: missing attribute id"))?;
                images.insert(id.trimmed().to_string(), self.desc.images.len());
                let path = self.dir.join(img.trimmed());
                self.desc.images.push(ImageDesc { path, loc: img.loc(self.path) });
            }
        }
        for map in t.all("TextureMap") {
            map.mark_used();
            let id = map.attr("id").ok_or_else(|| self.err(map, "<TextureMap>: missing attribute id"))?;
            let id = id.trimmed().to_string();
            let texture = self.texture_map(map, &id, &images)?;
            self.texture_ids.insert(id, vec![self.desc.textures.len()]);
            self.desc.textures.push(texture);
        }
        for tex in t.all("Texture") {
            tex.mark_used();
            self.legacy_texture(tex)?;
        }
        Ok(())
    }

    /// A pre-2022 `Texture`: one map for its decal mode, and a second one when it is also a bump map.
    fn legacy_texture(&mut self, tex: &Node) -> Result<()> {
        let p = self.path;
        let id = tex.attr("id").ok_or_else(|| self.err(tex, "<Texture>: missing attribute id"))?.trimmed().to_string();
        let name = format!("Texture {id}");
        let file = self.req(tex, "ImageName")?;
        let decal = self.decal_mode(tex, &name)?;
        let scale = if matches!(file.trimmed(), "perlin" | "checkerboard") {
            // Procedural values are already in [0, 1]: the files' Normalizer of 1 leaves them so.
            self.positive(tex, "Normalizer", &name)?;
            // A scale of 0 gives one value everywhere: one noise sample, one square of the board.
            self.positive(tex, "ScalingFactor", &name)?.unwrap_or(1.0)
        } else {
            match self.one(tex, "ScalingFactor") {
                Some(n) => n.float(p)?,
                None => 1.0,
            }
        };
        let appearance = self.one(tex, "Appearance").map(|n| (n, n.trimmed()));
        let source = match file.trimmed() {
            "perlin" => {
                let conversion = match appearance {
                    None | Some((_, "patch")) => NoiseConversion::Linear,
                    Some((_, "vein")) => NoiseConversion::AbsVal,
                    Some((n, other)) => return Err(self.err(n, format!("{name}: unknown Appearance '{other}'"))),
                };
                TextureSource::Perlin { conversion, scale }
            }
            "checkerboard" => self.checkerboard(tex, scale)?,
            path => {
                let (interpolation, normalizer) = self.image_sampling(tex, &name)?;
                let clamp = match appearance {
                    None | Some((_, "repeat")) => false,
                    Some((_, "clamp")) => true,
                    Some((n, other)) => return Err(self.err(n, format!("{name}: unknown Appearance '{other}'"))),
                };
                let image = self.desc.images.len();
                self.desc.images.push(ImageDesc { path: self.dir.join(path), loc: file.loc(p) });
                TextureSource::Image { image, interpolation, normalizer, clamp }
            }
        };
        let mut maps = vec![self.desc.textures.len()];
        let loc = tex.loc(p);
        let bump = match tex.attr("bumpmap") {
            Some(a) => a.boolean(p)?,
            None => false,
        };
        let bump_factor = match tex.attr("bumpmapMultiplier") {
            Some(a) => a.trimmed().parse::<f32>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                crate::Error::input(a.loc(p), format!("{name}: bumpmapMultiplier '{}' is not a number", a.trimmed()))
            })?,
            None => 1.0,
        };
        let desc = TextureDesc { id: id.clone(), source: source.clone(), decal, bump_factor, loc: loc.clone() };
        self.desc.textures.push(desc);
        if bump {
            maps.push(self.desc.textures.len());
            let decal = DecalMode::BumpNormal;
            self.desc.textures.push(TextureDesc { id: id.clone(), source, decal, bump_factor, loc });
        }
        self.texture_ids.insert(id, maps);
        Ok(())
    }

    /// The pre-2022 `BackgroundTexture`: an image spanning the image plane.
    pub(super) fn background_texture(&mut self, n: &Node) {
        let image = self.desc.images.len();
        self.desc.images.push(ImageDesc { path: self.dir.join(n.trimmed()), loc: n.loc(self.path) });
        let source =
            TextureSource::Image { image, interpolation: Interpolation::Nearest, normalizer: 255.0, clamp: true };
        let decal = DecalMode::ReplaceBackground;
        let t = TextureDesc { id: "background".into(), source, decal, bump_factor: 1.0, loc: n.loc(self.path) };
        self.desc.textures.push(t);
    }

    fn texture_map(&mut self, map: &Node, id: &str, images: &HashMap<String, usize>) -> Result<TextureDesc> {
        let p = self.path;
        let name = format!("TextureMap {id}");
        let kind = map.attr("type").ok_or_else(|| self.err(map, format!("{name}: missing attribute type")))?;
        let decal = self.decal_mode(map, &name)?;
        let bump_factor = match self.one(map, "BumpFactor") {
            Some(n) => n.float(p)?,
            None => 1.0,
        };
        let source = match kind.trimmed() {
            "image" => {
                let i = self.req(map, "ImageId")?;
                let image = *images.get(i.trimmed()).ok_or_else(|| {
                    self.err(i, format!("{name}: no <Image id=\"{}\"> in <Textures><Images>", i.trimmed()))
                })?;
                let (interpolation, normalizer) = self.image_sampling(map, &name)?;
                TextureSource::Image { image, interpolation, normalizer, clamp: false }
            }
            "perlin" => {
                let conversion = match self.one(map, "NoiseConversion").map(|n| (n, n.trimmed())) {
                    None | Some((_, "linear")) => NoiseConversion::Linear,
                    Some((_, "absval")) => NoiseConversion::AbsVal,
                    Some((n, other)) => return Err(self.err(n, format!("{name}: unknown NoiseConversion '{other}'"))),
                };
                let scale = self.positive(map, "NoiseScale", &name)?.unwrap_or(1.0);
                TextureSource::Perlin { conversion, scale }
            }
            "checkerboard" => {
                // Scale 0 puts every point in the square at the origin: one colour, no board.
                let scale = self.positive(map, "Scale", &name)?.unwrap_or(1.0);
                self.checkerboard(map, scale)?
            }
            other => return Err(Error::input(kind.loc(p), format!("{name}: unknown type '{other}'"))),
        };
        Ok(TextureDesc { id: id.to_string(), source, decal, bump_factor, loc: map.loc(p) })
    }

    fn decal_mode(&mut self, map: &Node, name: &str) -> Result<DecalMode> {
        let d = self.req(map, "DecalMode")?;
        Ok(match d.trimmed() {
            "replace_kd" => DecalMode::ReplaceKd,
            "blend_kd" => DecalMode::BlendKd,
            "replace_ks" => DecalMode::ReplaceKs,
            "replace_all" => DecalMode::ReplaceAll,
            "replace_background" => DecalMode::ReplaceBackground,
            "replace_normal" => DecalMode::ReplaceNormal,
            "bump_normal" => DecalMode::BumpNormal,
            other => return Err(self.err(d, format!("{name}: unknown DecalMode '{other}'"))),
        })
    }

    /// `Interpolation` (nearest when absent; an unknown value is reported and read as bilinear) and
    /// `Normalizer` (255 when absent) of an image texture.
    fn image_sampling(&mut self, map: &Node, name: &str) -> Result<(Interpolation, f32)> {
        let interpolation = match self.one(map, "Interpolation").map(|n| (n, n.trimmed())) {
            None | Some((_, "nearest")) => Interpolation::Nearest,
            Some((_, "bilinear")) => Interpolation::Bilinear,
            Some((_, "trilinear")) => Interpolation::Trilinear,
            Some((n, other)) => {
                let msg = format!("{name}: unknown Interpolation '{other}'; bilinear used");
                self.notes.plain(n.loc(self.path), msg);
                Interpolation::Bilinear
            }
        };
        Ok((interpolation, self.positive(map, "Normalizer", name)?.unwrap_or(255.0)))
    }

    /// A checkerboard's `Offset`, `BlackColor` and `WhiteColor`, with its `scale`.
    fn checkerboard(&mut self, map: &Node, scale: f32) -> Result<TextureSource> {
        let p = self.path;
        let mut color = |n: &str, c: f32| -> Result<Color> {
            Ok(match self.one(map, n) {
                Some(v) => v.vec3(p)?,
                None => Color::splat(c),
            })
        };
        let (black, white) = (color("BlackColor", 0.0)?, color("WhiteColor", 1.0)?);
        let offset = match self.one(map, "Offset") {
            Some(n) => n.float(p)?,
            None => 0.0,
        };
        Ok(TextureSource::Checkerboard { scale, offset, black, white })
    }

    /// The child `child` of `map` as a positive number, if present.
    fn positive(&mut self, map: &Node, child: &str, name: &str) -> Result<Option<f32>> {
        let Some(n) = self.one(map, child) else { return Ok(None) };
        let v = n.float(self.path)?;
        if v <= 0.0 {
            return Err(self.err(n, format!("{name}: {child} {v} must be positive")));
        }
        Ok(Some(v))
    }

    /// The maps an object names in its `Textures` element (or pre-2022 `Texture` elements), as indices.
    pub(super) fn object_textures(&mut self, o: &Node, name: &str) -> Result<Vec<usize>> {
        let mut out = Vec::new();
        let lists = self.one(o, "Textures").into_iter().chain(o.all("Texture"));
        for t in lists.collect::<Vec<_>>() {
            t.mark_used();
            for id in t.trimmed().split_whitespace() {
                let maps = self
                    .texture_ids
                    .get(id)
                    .ok_or_else(|| self.err(t, format!("{name}: no texture map with id '{id}'")))?;
                out.extend_from_slice(maps);
            }
        }
        Ok(out)
    }

    /// An inline mesh `o` with the maps `textures` needs `TexCoordData` when one of them samples an image
    /// at the surface's (u, v): without pairs every point would take the texel at (0, 0), one colour over
    /// the whole mesh. (A short `TexCoordData` is refused where a corner's id falls outside it.)
    pub(super) fn check_uvs_for_images(&self, o: &Node, name: &str, textures: &[usize]) -> Result<()> {
        if !self.uvs.is_empty() {
            return Ok(());
        }
        let image = textures
            .iter()
            .map(|&t| &self.desc.textures[t])
            .find(|t| matches!(t.source, TextureSource::Image { .. }) && t.decal != DecalMode::ReplaceBackground);
        let Some(t) = image else { return Ok(()) };
        let at = o.child("Textures").or_else(|| o.child("Texture")).unwrap_or(o);
        let msg = format!(
            "{name}: image texture '{}' needs texture coordinates, but TexCoordData has no (u, v) pairs (every \
             point would show the texel at (0, 0))",
            t.id
        );
        Err(self.err(at, msg))
    }

    /// `TexCoordData`: (u, v) pairs, numbered from 1 like the vertices.
    pub(super) fn tex_coord_data(&mut self, n: &Node) -> Result<()> {
        let f = n.floats(self.path)?;
        if f.len() % 2 != 0 {
            return Err(self.err(n, format!("<TexCoordData>: expected u v pairs, found {} numbers", f.len())));
        }
        self.uvs = f.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::super::{read, Form};
    use crate::scene::desc::{DecalMode, Interpolation, MeshSource, SceneDesc, ShapeDesc, TextureSource};
    use crate::scene::readers::xml;
    use crate::Result;

    const MATERIAL: &str = "<Materials><Material id=\"1\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                            <DiffuseReflectance>1 1 1</DiffuseReflectance></Material></Materials>";

    fn read_xml(body: &str) -> Result<SceneDesc> {
        let path = Path::new("t.xml");
        read(&xml::parse(&format!("<Scene>{MATERIAL}{body}</Scene>"), path)?, path, Form::Xml)
    }

    fn textures(maps: &str) -> String {
        format!("<Textures><Images><Image id=\"1\">a.png</Image></Images>{maps}</Textures>")
    }

    #[test]
    fn metu_texture_maps_are_read_with_their_defaults() {
        let body = textures(
            "<TextureMap id=\"1\" type=\"image\"><ImageId>1</ImageId><DecalMode>blend_kd</DecalMode></TextureMap>\
             <TextureMap id=\"2\" type=\"checkerboard\"><DecalMode>replace_kd</DecalMode><Scale>2</Scale>\
             </TextureMap>",
        )
            + "<VertexData>0 0 0 1 0 0 0 1 0</VertexData><TexCoordData>0 0 1 0 0 1 1 1</TexCoordData><Objects>\
             <Mesh id=\"1\"><Material>1</Material><Textures>2 1</Textures>\
             <Faces textureOffset=\"1\">1 2 3</Faces></Mesh></Objects>";
        let d = read_xml(&body).unwrap();
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        assert_eq!(d.images.len(), 1);
        assert_eq!(d.textures[0].decal, DecalMode::BlendKd);
        let TextureSource::Image { image: 0, interpolation, normalizer, .. } = d.textures[0].source else {
            panic!("{:?}", d.textures[0].source)
        };
        assert_eq!((interpolation, normalizer), (Interpolation::Nearest, 255.0));
        assert!(matches!(d.textures[1].source, TextureSource::Checkerboard { scale: 2.0, offset: 0.0, .. }));
        assert_eq!(d.objects[0].textures, [1, 0]);
        let ShapeDesc::Mesh { source: MeshSource::Inline(m), .. } = &d.objects[0].shape else { panic!() };
        // Corner ids 1 2 3 plus textureOffset 1 take pairs 2 3 4.
        let uvs = m.uvs.as_ref().unwrap();
        assert_eq!(uvs.iter().map(|v| v.to_array()).collect::<Vec<_>>(), [[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]);
    }

    #[test]
    fn metu_pre_2022_textures_become_maps_and_bump_maps() {
        let body = "<BackgroundTexture>sky.jpg</BackgroundTexture><Textures>\
                    <Texture id=\"1\" bumpmap=\"true\" bumpmapMultiplier=\"30\"><ImageName>a.jpg</ImageName>\
                    <Interpolation>bilinear</Interpolation><DecalMode>replace_kd</DecalMode>\
                    <Appearance>clamp</Appearance></Texture>\
                    <Texture id=\"2\"><ImageName>perlin</ImageName><ScalingFactor>3</ScalingFactor>\
                    <Appearance>vein</Appearance><DecalMode>blend_kd</DecalMode><Normalizer>1</Normalizer></Texture>\
                    </Textures><VertexData>0 0 0</VertexData><Objects><Sphere id=\"1\"><Material>1</Material>\
                    <Texture>1</Texture><Texture>2</Texture><Center>1</Center><Radius>1</Radius></Sphere></Objects>";
        let d = read_xml(body).unwrap();
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        let decals: Vec<DecalMode> = d.textures.iter().map(|t| t.decal).collect();
        assert_eq!(
            decals,
            [DecalMode::ReplaceKd, DecalMode::BumpNormal, DecalMode::BlendKd, DecalMode::ReplaceBackground]
        );
        assert_eq!(d.textures[1].bump_factor, 30.0);
        assert!(matches!(d.textures[0].source, TextureSource::Image { clamp: true, image: 0, .. }));
        assert!(matches!(
            d.textures[2].source,
            TextureSource::Perlin { conversion: crate::scene::desc::NoiseConversion::AbsVal, scale: 3.0 }
        ));
        assert_eq!(d.objects[0].textures, [0, 1, 2]);
    }

    #[test]
    fn metu_interpolation_reads_trilinear_and_reports_unknown_values() {
        let interpolation = |value: &str, legacy: bool| {
            let i = format!("<Interpolation>{value}</Interpolation><DecalMode>replace_kd</DecalMode>");
            let body = if legacy {
                format!("<Textures><Texture id=\"1\"><ImageName>a.png</ImageName>{i}</Texture></Textures>")
            } else {
                textures(&format!("<TextureMap id=\"1\" type=\"image\"><ImageId>1</ImageId>{i}</TextureMap>"))
            };
            let d = read_xml(&body).unwrap();
            let TextureSource::Image { interpolation, .. } = d.textures[0].source else { panic!() };
            (interpolation, d.warnings)
        };
        for legacy in [false, true] {
            assert_eq!(interpolation("trilinear", legacy), (Interpolation::Trilinear, Vec::<String>::new()));
            assert_eq!(interpolation(" nearest ", legacy), (Interpolation::Nearest, Vec::<String>::new()));
            let (i, warnings) = interpolation("cubic", legacy);
            assert_eq!(i, Interpolation::Bilinear);
            assert_eq!(warnings.len(), 1);
            assert!(warnings[0].contains("unknown Interpolation 'cubic'; bilinear used"), "{warnings:?}");
            assert!(warnings[0].starts_with("t.xml:1:"), "{warnings:?}");
        }
    }

    #[test]
    fn metu_texture_maps_mark_a_file_as_post_2020_for_untyped_mirrors() {
        let mirror = "<Materials><Material id=\"1\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                      <DiffuseReflectance>1 1 1</DiffuseReflectance>\
                      <MirrorReflectance>1 1 1</MirrorReflectance></Material></Materials>";
        let kind = |textures: &str| {
            let path = Path::new("t.xml");
            let body = format!("<Scene><MaxRecursionDepth>6</MaxRecursionDepth>{mirror}{textures}</Scene>");
            read(&xml::parse(&body, path).unwrap(), path, Form::Xml).unwrap().materials[0].kind.clone()
        };
        assert!(matches!(kind(""), crate::scene::desc::MaterialKind::Mirror { .. }));
        let maps = textures(
            "<TextureMap id=\"1\" type=\"image\"><ImageId>1</ImageId>\
                             <DecalMode>replace_kd</DecalMode></TextureMap>",
        );
        assert_eq!(kind(&maps), crate::scene::desc::MaterialKind::BlinnPhong);
    }

    #[test]
    fn metu_texture_errors_are_located() {
        let map = |inner: &str| {
            textures(&format!("<TextureMap id=\"1\" type=\"image\"><ImageId>1</ImageId>{inner}</TextureMap>"))
        };
        let err = |body: String| read_xml(&body).unwrap_err().to_string();
        assert_eq!(err(map("<DecalMode>paint</DecalMode>")), "t.xml:1:257: TextureMap 1: unknown DecalMode 'paint'");
        assert_eq!(
            err(map("<DecalMode>replace_kd</DecalMode><Normalizer>-1</Normalizer>")),
            "t.xml:1:290: TextureMap 1: Normalizer -1 must be positive"
        );
        assert_eq!(
            err(textures(
                "<TextureMap id=\"1\" type=\"perlin\"><DecalMode>replace_kd</DecalMode>\
                          <NoiseScale>0</NoiseScale></TextureMap>"
            )),
            "t.xml:1:271: TextureMap 1: NoiseScale 0 must be positive"
        );
        assert_eq!(
            err(textures("<TextureMap id=\"1\" type=\"wood\"><DecalMode>replace_kd</DecalMode></TextureMap>")),
            "t.xml:1:224: TextureMap 1: unknown type 'wood'"
        );
        assert_eq!(
            err(map("<DecalMode>replace_kd</DecalMode>")
                + "<VertexData>0 0 0</VertexData><Objects><Sphere id=\"1\"><Material>1</Material>\
                   <Textures>2</Textures><Center>1</Center><Radius>1</Radius></Sphere></Objects>"),
            "t.xml:1:390: Sphere 1: no texture map with id '2'"
        );
        assert_eq!(
            err("<VertexData>0 0 0 1 0 0 0 1 0</VertexData><TexCoordData>0 0 1 0</TexCoordData><Objects>\
                 <Mesh id=\"1\"><Material>1</Material><Faces>1 2 3</Faces></Mesh></Objects>"
                .to_string()),
            "t.xml:1:273: Mesh 1: texture coordinate 3 out of range (TexCoordData has 2 pairs, numbered from 1)"
        );
    }
}
