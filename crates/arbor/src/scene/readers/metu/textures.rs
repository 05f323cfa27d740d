//! The `Textures` of a METU scene (CENG 795 2022 hw4): `Images` (file names by id) and `TextureMap`s
//! of type `image`, `perlin` or `checkerboard`, each with its `DecalMode`; objects name their maps in
//! their own `Textures` element. `TexCoordData` holds the (u, v) pairs of inline meshes.

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
            self.texture_ids.insert(id, self.desc.textures.len());
            self.desc.textures.push(texture);
        }
        self.unsupported(t, "Texture", "textures in the pre-2022 form are");
        Ok(())
    }

    fn texture_map(&mut self, map: &Node, id: &str, images: &HashMap<String, usize>) -> Result<TextureDesc> {
        let p = self.path;
        let name = format!("TextureMap {id}");
        let kind = map.attr("type").ok_or_else(|| self.err(map, format!("{name}: missing attribute type")))?;
        let d = self.req(map, "DecalMode")?;
        let decal = match d.trimmed() {
            "replace_kd" => DecalMode::ReplaceKd,
            "blend_kd" => DecalMode::BlendKd,
            "replace_ks" => DecalMode::ReplaceKs,
            "replace_all" => DecalMode::ReplaceAll,
            "replace_background" => DecalMode::ReplaceBackground,
            "replace_normal" => DecalMode::ReplaceNormal,
            "bump_normal" => DecalMode::BumpNormal,
            other => return Err(self.err(d, format!("{name}: unknown DecalMode '{other}'"))),
        };
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
                let interpolation = match self.one(map, "Interpolation").map(|n| (n, n.trimmed())) {
                    None | Some((_, "nearest")) => Interpolation::Nearest,
                    Some((_, "bilinear")) => Interpolation::Bilinear,
                    Some((n, other)) => {
                        let msg = format!("{name}: unknown Interpolation '{other}'; bilinear used");
                        self.notes.plain(n.loc(p), msg);
                        Interpolation::Bilinear
                    }
                };
                let normalizer = self.positive(map, "Normalizer", &name)?.unwrap_or(255.0);
                let degamma = match map.attr("degamma") {
                    Some(a) => a.boolean(p)?,
                    None => false,
                };
                TextureSource::Image { image, interpolation, normalizer, degamma }
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
                let color = |r: &mut Self, n: &str, c: f32| -> Result<Color> {
                    Ok(match r.one(map, n) {
                        Some(v) => v.vec3(p)?,
                        None => Color::splat(c),
                    })
                };
                let scale = match self.one(map, "Scale") {
                    Some(n) => n.float(p)?,
                    None => 1.0,
                };
                let offset = match self.one(map, "Offset") {
                    Some(n) => n.float(p)?,
                    None => 0.0,
                };
                let (black, white) = (color(self, "BlackColor", 0.0)?, color(self, "WhiteColor", 1.0)?);
                TextureSource::Checkerboard { scale, offset, black, white }
            }
            other => return Err(Error::input(kind.loc(p), format!("{name}: unknown type '{other}'"))),
        };
        Ok(TextureDesc { id: id.to_string(), source, decal, bump_factor, loc: map.loc(p) })
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

    /// The maps an object names in its `Textures` element, as indices.
    pub(super) fn object_textures(&mut self, o: &Node, name: &str) -> Result<Vec<usize>> {
        let Some(t) = self.one(o, "Textures") else { return Ok(Vec::new()) };
        let mut out = Vec::new();
        for id in t.trimmed().split_whitespace() {
            let i = *self
                .texture_ids
                .get(id)
                .ok_or_else(|| self.err(t, format!("{name}: no <TextureMap id=\"{id}\"> in <Textures>")))?;
            out.push(i);
        }
        Ok(out)
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
            "t.xml:1:390: Sphere 1: no <TextureMap id=\"2\"> in <Textures>"
        );
        assert_eq!(
            err("<VertexData>0 0 0 1 0 0 0 1 0</VertexData><TexCoordData>0 0 1 0</TexCoordData><Objects>\
                 <Mesh id=\"1\"><Material>1</Material><Faces>1 2 3</Faces></Mesh></Objects>"
                .to_string()),
            "t.xml:1:273: Mesh 1: texture coordinate 3 out of range (TexCoordData has 2 pairs, numbered from 1)"
        );
    }
}
