//! The TOML scene format (see README "Scene format"), parsed with serde and checked field by
//! field; every error carries the file, the line of the offending value and the field's path.

use super::builder::{wound, SceneTables};
use super::closed_surface::check_closed_outward;
use super::environment::EnvironmentMap;
use super::error::{line_of, SceneError};
use super::instancing::INSTANCE_MIN_TRIANGLES;
use super::light_table::sphere_light;
use super::mesh::{load_mesh, TriangleSoup};
use super::transform::{parse_transform, TransformFields};
use super::{CameraDesc, Scene, TriangleGroup};
use crate::settings::RenderSettings;
use glam::Vec3;
use kernel::scene::{ShadingTriangle, Sphere, NONE};
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::rc::Rc;
use toml::Spanned;

/// The built-in default scene: the Cornell scene of `scenes/cornell.toml`, embedded.
pub const DEFAULT_SCENE_TOML: &str = include_str!("../../../scenes/cornell.toml");
/// The name errors and outputs use for the built-in scene.
pub const DEFAULT_SCENE_NAME: &str = "cornell.toml";

/// Largest coordinate magnitude (and sphere radius) accepted: the kernel's f32 arithmetic
/// squares distances, and (3.5e15)^2 stays far below f32's 3.4e38 (property tests).
pub const MAX_COORDINATE: f32 = 1e15;
/// Smallest sphere radius accepted: below it, 1 / (4 pi r^2) overflows f32.
pub const MIN_RADIUS: f32 = 1e-15;

/// Largest image side accepted (a typo like 1e9 must not try to allocate the film).
pub const MAX_IMAGE_SIDE: i64 = 1 << 15;

pub(super) type V3 = Spanned<[f32; 3]>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: Spanned<CameraFile>,
    /// Settings by name (`crate::settings`), each value with its place in the file.
    #[serde(default)]
    render: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<MaterialFile>>,
    #[serde(default)]
    sphere: Vec<Spanned<SphereFile>>,
    #[serde(default)]
    quad: Vec<Spanned<QuadFile>>,
    #[serde(default)]
    mesh: Vec<Spanned<MeshFile>>,
    #[serde(default)]
    gltf: Vec<Spanned<GltfFile>>,
    #[serde(default)]
    light: Vec<Spanned<LightFile>>,
    #[serde(default)]
    background: Option<BackgroundFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFile {
    eye: V3,
    look_at: V3,
    up: V3,
    vfov: Spanned<f32>,
    width: Spanned<i64>,
    height: Spanned<i64>,
    /// Thin-lens diameter (default 0: a pinhole).
    aperture: Option<Spanned<f32>>,
    /// Distance of the plane in focus along the view axis (default: |look_at - eye|).
    focus_distance: Option<Spanned<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialFile {
    pub kd: Option<V3>,
    pub ks: Option<V3>,
    pub alpha: Option<Spanned<f32>>,
    pub conductor: Option<Spanned<toml::Value>>,
    pub dielectric: Option<Spanned<DielectricFile>>,
    pub emission: Option<V3>,
    /// With `emission`, on quads and meshes: both faces emit (default: the front face).
    pub two_sided: Option<Spanned<bool>>,
    /// Image textures multiplying kd, ks, alpha (its red channel) and emission (each factor
    /// defaults to 1 where its map is given), relative to the scene file.
    pub kd_map: Option<Spanned<String>>,
    pub ks_map: Option<Spanned<String>>,
    pub alpha_map: Option<Spanned<String>>,
    pub emission_map: Option<Spanned<String>>,
    /// How the maps continue outside [0, 1]: "repeat" (default), "clamp" or "mirror".
    pub wrap: Option<Spanned<String>>,
    /// glTF's metallic-roughness material (`material_kind::METALLIC_ROUGHNESS`): base colour,
    /// metalness and perceptual roughness (alpha = roughness^2), each optional (defaults 1, as
    /// in glTF), with glTF's maps: the base colour (sRGB) and the metallic-roughness map (linear;
    /// blue metalness, green roughness).
    pub base_color: Option<V3>,
    pub metallic: Option<Spanned<f32>>,
    pub roughness: Option<Spanned<f32>>,
    pub base_color_map: Option<Spanned<String>>,
    pub metallic_roughness_map: Option<Spanned<String>>,
    /// A tangent-space normal map (linear; glTF's `normalTexture`, OpenGL's +y convention) and
    /// its x/y scale (default 1), for any reflecting material on triangles.
    pub normal_map: Option<Spanned<String>>,
    pub normal_scale: Option<Spanned<f32>>,
}

impl MaterialFile {
    /// Whether the entry describes glTF's metallic-roughness material.
    pub fn is_metallic_roughness(&self) -> bool {
        self.base_color.is_some()
            || self.metallic.is_some()
            || self.roughness.is_some()
            || self.base_color_map.is_some()
            || self.metallic_roughness_map.is_some()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DielectricFile {
    pub ior: Spanned<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereFile {
    center: V3,
    radius: Spanned<f32>,
    material: Spanned<String>,
    /// Optional transform (`transform::parse_transform`): scale (a number or [x, y, z]), then
    /// rotate ([degrees, axis x, y, z]), then translate; or a row-major 4 x 4 affine matrix.
    scale: Option<Spanned<toml::Value>>,
    rotate: Option<Spanned<[f32; 4]>>,
    translate: Option<V3>,
    matrix: Option<Spanned<[[f32; 4]; 4]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct QuadFile {
    corner: V3,
    edge1: V3,
    edge2: V3,
    material: Spanned<String>,
    /// Optional transform (`transform::parse_transform`): scale (a number or [x, y, z]), then
    /// rotate ([degrees, axis x, y, z]), then translate; or a row-major 4 x 4 affine matrix.
    scale: Option<Spanned<toml::Value>>,
    rotate: Option<Spanned<[f32; 4]>>,
    translate: Option<V3>,
    matrix: Option<Spanned<[[f32; 4]; 4]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshFile {
    file: Spanned<String>,
    material: Spanned<String>,
    /// Optional transform (`transform::parse_transform`): scale (a number or [x, y, z]), then
    /// rotate ([degrees, axis x, y, z]), then translate; or a row-major 4 x 4 affine matrix.
    scale: Option<Spanned<toml::Value>>,
    rotate: Option<Spanned<[f32; 4]>>,
    translate: Option<V3>,
    matrix: Option<Spanned<[[f32; 4]; 4]>>,
}

/// The transform fields of a shape's table (`transform::TransformFields`).
macro_rules! transform_fields {
    ($f:expr) => {
        TransformFields {
            scale: $f.scale.as_ref(),
            rotate: $f.rotate.as_ref(),
            translate: $f.translate.as_ref(),
            matrix: $f.matrix.as_ref(),
        }
    };
}

/// A point light, or with `direction` a spot light (glTF's `KHR_lights_punctual`): radiant
/// `intensity` (per steradian, RGB) at `position`; a spot's falloff runs from `inner_angle` to
/// `outer_angle` (cone half-angles in degrees, glTF's defaults 0 and 45).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightFile {
    position: Option<V3>,
    intensity: Option<V3>,
    /// A directional light's irradiance (with `direction`, without `position`).
    irradiance: Option<V3>,
    direction: Option<V3>,
    inner_angle: Option<Spanned<f32>>,
    outer_angle: Option<Spanned<f32>>,
}

/// A glTF file's default scene as part of this one (`gltf_scene::include`): its meshes with
/// their own materials, under an optional transform; its cameras are not used.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GltfFile {
    file: Spanned<String>,
    scale: Option<Spanned<toml::Value>>,
    rotate: Option<Spanned<[f32; 4]>>,
    translate: Option<V3>,
    matrix: Option<Spanned<[[f32; 4]; 4]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BackgroundFile {
    /// A uniform environment.
    radiance: Option<V3>,
    /// An equirectangular environment map (EXR or HDR), relative to the scene file.
    map: Option<Spanned<String>>,
    /// Factor on the map's texels (default 1).
    scale: Option<Spanned<f32>>,
    /// The map's rotation about the up axis (+y), degrees (default 0).
    rotation: Option<Spanned<f32>>,
}

/// Checks values and reports errors at their line.
pub(super) struct Checker<'a> {
    pub path: &'a Path,
    pub text: &'a str,
}

impl Checker<'_> {
    pub fn err(
        &self,
        span: std::ops::Range<usize>,
        field: &str,
        msg: impl Into<String>,
    ) -> SceneError {
        SceneError::new(self.path, Some(line_of(self.text, span.start)), field, msg)
    }

    pub fn vec3(&self, v: &V3, field: &str) -> Result<Vec3, SceneError> {
        let a = *v.get_ref();
        if !a.iter().all(|c| c.is_finite()) {
            Err(self.err(v.span(), field, format!("{a:?} is not finite")))
        } else if !a.iter().all(|c| c.abs() <= MAX_COORDINATE) {
            Err(self.err(
                v.span(),
                field,
                format!("{a:?} has a component beyond {MAX_COORDINATE:e} (the range the renderer supports)"),
            ))
        } else {
            Ok(Vec3::from(a))
        }
    }

    pub fn color(&self, v: &V3, field: &str, max: Option<f32>) -> Result<Vec3, SceneError> {
        let c = self.vec3(v, field)?;
        if c.min_element() < 0.0 {
            return Err(self.err(
                v.span(),
                field,
                format!("{:?} has a negative component", c.to_array()),
            ));
        }
        if let Some(max) = max {
            if c.max_element() > max {
                return Err(self.err(
                    v.span(),
                    field,
                    format!("{:?} has a component above {max} (a surface cannot reflect more than it receives)", c.to_array()),
                ));
            }
        }
        Ok(c)
    }

    fn int(&self, v: &Spanned<i64>, field: &str, min: i64, max: i64) -> Result<u32, SceneError> {
        let x = *v.get_ref();
        if x < min || x > max {
            Err(self.err(v.span(), field, format!("{x} is outside {min}..={max}")))
        } else {
            Ok(x as u32)
        }
    }
}

/// Parses and validates scene text; `path` names the file in errors and anchors mesh paths.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        let field = "syntax";
        SceneError::new(path, line, field, e.message().trim().to_string())
    })?;
    let ck = Checker { path, text };

    // Camera.
    let cam = file.camera.get_ref();
    let eye = ck.vec3(&cam.eye, "camera.eye")?;
    let look_at = ck.vec3(&cam.look_at, "camera.look_at")?;
    let up = ck.vec3(&cam.up, "camera.up")?;
    let vfov = *cam.vfov.get_ref();
    if !(vfov > 0.0 && vfov < 180.0) {
        return Err(ck.err(
            cam.vfov.span(),
            "camera.vfov",
            format!("{vfov} is not in (0, 180) degrees"),
        ));
    }
    let width = ck.int(&cam.width, "camera.width", 1, MAX_IMAGE_SIDE)?;
    let height = ck.int(&cam.height, "camera.height", 1, MAX_IMAGE_SIDE)?;
    let forward = look_at - eye;
    if !(forward.length() > 0.0) || !forward.normalize().is_finite() {
        return Err(ck.err(
            cam.look_at.span(),
            "camera.look_at",
            "equals camera.eye: no viewing direction",
        ));
    }
    let right = forward.normalize().cross(up);
    if !(right.length() > 1e-6 * up.length()) || !right.normalize().is_finite() {
        return Err(ck.err(
            cam.up.span(),
            "camera.up",
            "is zero or parallel to the viewing direction",
        ));
    }
    let aperture = match &cam.aperture {
        Some(a) => {
            let x = *a.get_ref();
            if !(0.0..=MAX_COORDINATE).contains(&x) {
                return Err(ck.err(
                    a.span(),
                    "camera.aperture",
                    format!("{x} is not a lens diameter in 0..={MAX_COORDINATE:e}"),
                ));
            }
            x
        }
        None => 0.0,
    };
    let focus_distance = match &cam.focus_distance {
        Some(f) => {
            let x = *f.get_ref();
            if !(x > 0.0 && x <= MAX_COORDINATE) {
                return Err(ck.err(
                    f.span(),
                    "camera.focus_distance",
                    format!("{x} is not a distance in (0, {MAX_COORDINATE:e}]"),
                ));
            }
            x
        }
        None => forward.length(),
    };
    let camera = CameraDesc {
        eye,
        look_at,
        up,
        vfov_degrees: vfov,
        width,
        height,
        aperture,
        focus_distance,
    };

    // Render settings: each through the one vocabulary, in the file's order.
    let mut render = RenderSettings::default();
    let mut settings: Vec<_> = file.render.iter().collect();
    settings.sort_by_key(|(_, v)| v.span().start);
    for (key, value) in settings {
        let text = match value.get_ref() {
            toml::Value::String(s) => s.clone(),
            toml::Value::Integer(i) => i.to_string(),
            toml::Value::Float(f) => f.to_string(),
            toml::Value::Boolean(b) => b.to_string(),
            other => {
                return Err(ck.err(
                    value.span(),
                    &format!("render.{key}"),
                    format!("a {} is not a setting's value", other.type_str()),
                ))
            }
        };
        render
            .set(key, &text)
            .map_err(|m| ck.err(value.span(), &format!("render.{key}"), m))?;
    }

    // Materials, in name order.
    let mut tables = SceneTables::default();
    let base_dir = path.parent().unwrap_or(Path::new("."));
    for (name, m) in &file.materials {
        let field = format!("materials.{name}");
        let mut material = super::materials::material(&ck, &field, m)?;
        super::materials::attach_textures(
            &ck,
            &field,
            m,
            base_dir,
            &mut tables.textures,
            &mut material,
        )?;
        tables.add_material(name.clone(), material);
    }
    let material_names = tables.material_names.clone();
    let find_material = |s: &Spanned<String>, field: &str| -> Result<u32, SceneError> {
        material_names
            .iter()
            .position(|n| n == s.get_ref())
            .map(|i| i as u32)
            .ok_or_else(|| {
                ck.err(
                    s.span(),
                    field,
                    format!(
                        "unknown material '{}' (defined: {})",
                        s.get_ref(),
                        material_names.join(", ")
                    ),
                )
            })
    };

    // Spheres; emissive ones become lights.
    for (i, s) in file.sphere.iter().enumerate() {
        let sf = s.get_ref();
        let center = ck.vec3(&sf.center, &format!("sphere[{i}].center"))?;
        let radius = *sf.radius.get_ref();
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ck.err(
                sf.radius.span(),
                &format!("sphere[{i}].radius"),
                format!("{radius} must be a positive finite number"),
            ));
        }
        if !(MIN_RADIUS..=MAX_COORDINATE).contains(&radius) {
            return Err(ck.err(
                sf.radius.span(),
                &format!("sphere[{i}].radius"),
                format!("{radius:e} is outside {MIN_RADIUS:e}..={MAX_COORDINATE:e} (the range the renderer supports)"),
            ));
        }
        let (center, radius) = if transform_fields!(sf).is_given() {
            let field = format!("sphere[{i}]");
            let t = parse_transform(&ck, &field, &transform_fields!(sf))?;
            let Some(k) = t.uniform_scale() else {
                return Err(ck.err(
                    s.span(),
                    &field,
                    "a sphere takes a uniform scale and rotations only (it would become an \
                     ellipsoid)",
                ));
            };
            let (c, r) = (t.point(center), radius * k);
            if !(MIN_RADIUS..=MAX_COORDINATE).contains(&r) || c.abs().max_element() > MAX_COORDINATE
            {
                return Err(ck.err(
                    s.span(),
                    &field,
                    format!("transformed, centre {c} and radius {r:e} leave the range the renderer supports"),
                ));
            }
            (c, r)
        } else {
            (center, radius)
        };
        let material = find_material(&sf.material, &format!("sphere[{i}].material"))?;
        if tables.is_textured(material) {
            return Err(ck.err(
                sf.material.span(),
                &format!("sphere[{i}].material"),
                format!(
                    "'{}' has textures: spheres have no texture coordinates (textures are for \
                     quads and meshes)",
                    sf.material.get_ref()
                ),
            ));
        }
        if tables.materials[material as usize].two_sided != 0 {
            return Err(ck.err(
                sf.material.span(),
                &format!("sphere[{i}].material"),
                format!(
                    "'{}' is two-sided: a sphere emits from its outside only (two_sided is for \
                     quads and meshes)",
                    sf.material.get_ref()
                ),
            ));
        }
        let light = if tables.is_emissive(material) {
            tables.lights.push(sphere_light(
                center,
                radius,
                tables.materials[material as usize].emission,
            ));
            (tables.lights.len() - 1) as u32
        } else {
            NONE
        };
        tables.spheres.push(Sphere {
            center: center.to_array(),
            radius,
            material,
            light,
            _pad: [0; 2],
        });
    }

    // Quads (two triangles each) and meshes; each triangle of an emissive one is a light.
    // A quad's texture coordinates: (0, 0) at its corner, (1, 0) along edge1, (0, 1) along edge2.
    let quad_uv = |corners: [[f32; 2]; 3]| ShadingTriangle {
        normal0: [0.0; 3],
        normal1: [0.0; 3],
        normal2: [0.0; 3],
        uv0: corners[0],
        uv1: corners[1],
        uv2: corners[2],
        has_normals: 0,
    };
    let quads_start = tables.triangles.len();
    for (i, q) in file.quad.iter().enumerate() {
        let qf = q.get_ref();
        let field = format!("quad[{i}]");
        let mut corner = ck.vec3(&qf.corner, &format!("{field}.corner"))?;
        let mut e1 = ck.vec3(&qf.edge1, &format!("{field}.edge1"))?;
        let mut e2 = ck.vec3(&qf.edge2, &format!("{field}.edge2"))?;
        let mut mirror = false;
        if transform_fields!(qf).is_given() {
            let t = parse_transform(&ck, &field, &transform_fields!(qf))?;
            corner = t.point(corner);
            e1 = t.vector(e1);
            e2 = t.vector(e2);
            mirror = t.mirrors();
            if [corner, corner + e1 + e2]
                .iter()
                .any(|p| p.abs().max_element() > MAX_COORDINATE)
            {
                return Err(ck.err(
                    q.span(),
                    &field,
                    format!("a corner lies beyond {MAX_COORDINATE:e} after the transform"),
                ));
            }
        }
        let area = e1.cross(e2).length();
        if !(area > 0.0) || !area.is_finite() {
            return Err(ck.err(
                qf.edge2.span(),
                &format!("{field}.edge2"),
                "edges are zero or parallel: the quad has zero area",
            ));
        }
        let material = find_material(&qf.material, &format!("{field}.material"))?;
        if tables.is_dielectric(material) {
            return Err(ck.err(
                qf.material.span(),
                &format!("{field}.material"),
                format!(
                    "'{}' is a dielectric: it needs a closed surface (a sphere or a closed mesh) \
                     to have an inside, and a quad has none",
                    qf.material.get_ref()
                ),
            ));
        }
        let textured = tables.is_textured(material);
        // A mirroring transform reverses the winding, which keeps the front face the side the
        // untransformed quad's front maps to.
        tables.push_triangle(
            wound([corner, corner + e1, corner + e1 + e2], mirror),
            material,
            textured.then(|| quad_uv(wound([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], mirror))),
            None,
        );
        tables.push_triangle(
            wound([corner, corner + e1 + e2, corner + e2], mirror),
            material,
            textured.then(|| quad_uv(wound([[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]], mirror))),
            None,
        );
    }
    if tables.triangles.len() > quads_start {
        tables.triangle_groups.push(TriangleGroup {
            name: "quads".into(),
            range: quads_start..tables.triangles.len(),
        });
    }
    // A mesh file that several entries place with the same material is read once; from
    // INSTANCE_MIN_TRIANGLES triangles on and unless it emits, it is stored once and instanced.
    let mesh_key = |mf: &MeshFile| (mf.file.get_ref().clone(), mf.material.get_ref().clone());
    let mut mesh_uses: HashMap<(String, String), usize> = HashMap::new();
    for m in &file.mesh {
        *mesh_uses.entry(mesh_key(m.get_ref())).or_insert(0) += 1;
    }
    let mut loaded: HashMap<(String, String), Rc<TriangleSoup>> = HashMap::new();
    let mut instanced: HashMap<(String, String), u32> = HashMap::new();
    for (i, m) in file.mesh.iter().enumerate() {
        let mf = m.get_ref();
        let field = format!("mesh[{i}]");
        let material = find_material(&mf.material, &format!("{field}.material"))?;
        let mesh_path = base_dir.join(mf.file.get_ref());
        if !mesh_path.is_file() {
            return Err(ck.err(
                mf.file.span(),
                &format!("{field}.file"),
                format!("mesh file {} does not exist", mesh_path.display()),
            ));
        }
        let transform = if transform_fields!(mf).is_given() {
            Some(parse_transform(&ck, &field, &transform_fields!(mf))?)
        } else {
            None
        };
        let key = mesh_key(mf);
        if let Some(&mesh) = instanced.get(&key) {
            tables
                .add_instance(mesh, &transform.unwrap_or_default())
                .map_err(|msg| ck.err(m.span(), &field, msg))?;
            continue;
        }
        let soup = match loaded.get(&key) {
            Some(soup) => soup.clone(),
            None => Rc::new(load_mesh(&mesh_path)?),
        };
        if tables.is_dielectric(material) {
            check_closed_outward(&soup.triangles).map_err(|msg| {
                SceneError::new(
                    &mesh_path,
                    None,
                    format!("{field} (material '{}')", mf.material.get_ref()),
                    msg,
                )
            })?;
        }
        if tables.is_textured(material) && soup.uvs.is_empty() {
            return Err(ck.err(
                mf.material.span(),
                &format!("{field}.material"),
                format!(
                    "'{}' has textures but {} has no texture coordinates (OBJ vt, PLY u v)",
                    mf.material.get_ref(),
                    mf.file.get_ref()
                ),
            ));
        }
        let triangle_err = |(k, msg): (usize, String)| {
            ck.err(mf.file.span(), &format!("{field} triangle {k}"), msg)
        };
        if mesh_uses[&key] >= 2
            && soup.triangles.len() >= INSTANCE_MIN_TRIANGLES
            && !tables.is_emissive(material)
        {
            let mesh = tables.begin_instanced_mesh(mf.file.get_ref().clone());
            tables
                .push_mesh_part(&soup, material)
                .map_err(triangle_err)?;
            tables
                .add_instance(mesh, &transform.unwrap_or_default())
                .map_err(|msg| ck.err(m.span(), &field, msg))?;
            instanced.insert(key, mesh);
            continue;
        }
        tables
            .push_mesh(
                mf.file.get_ref().clone(),
                &soup,
                transform.as_ref(),
                material,
            )
            .map_err(triangle_err)?;
        if mesh_uses[&key] >= 2 {
            loaded.insert(key, soup);
        }
    }

    for (i, l) in file.light.iter().enumerate() {
        let lf = l.get_ref();
        let field = format!("light[{i}]");
        if let Some(irradiance) = &lf.irradiance {
            // A directional light: a direction and an irradiance, nothing else.
            let extra = [
                ("position", lf.position.is_some()),
                ("intensity", lf.intensity.is_some()),
                ("inner_angle", lf.inner_angle.is_some()),
                ("outer_angle", lf.outer_angle.is_some()),
            ];
            if let Some((name, _)) = extra.iter().find(|e| e.1) {
                return Err(ck.err(
                    l.span(),
                    &field,
                    format!(
                        "gives irradiance (a directional light) and {name}: a directional light \
                         has a direction and an irradiance only"
                    ),
                ));
            }
            let Some(d) = &lf.direction else {
                return Err(ck.err(
                    l.span(),
                    &field,
                    "a directional light (irradiance) needs the direction its light travels",
                ));
            };
            let travel = ck.vec3(d, &format!("{field}.direction"))?;
            if !(travel.length() > 0.0) {
                return Err(ck.err(d.span(), &format!("{field}.direction"), "is zero"));
            }
            let e = ck.color(irradiance, &format!("{field}.irradiance"), None)?;
            tables
                .lights
                .push(super::light_table::directional_light(travel, e.to_array()));
            continue;
        }
        let (Some(position), Some(intensity)) = (&lf.position, &lf.intensity) else {
            return Err(ck.err(
                l.span(),
                &field,
                "needs position and intensity (a point or spot light) or direction and \
                 irradiance (a directional light)",
            ));
        };
        let position = ck.vec3(position, &format!("{field}.position"))?;
        let intensity = ck.color(intensity, &format!("{field}.intensity"), None)?;
        let angle = |a: &Option<Spanned<f32>>, name: &str, default: f32| match a {
            None => Ok(default),
            Some(x) => {
                let v = *x.get_ref();
                if (0.0..=90.0).contains(&v) {
                    Ok(v)
                } else {
                    Err(ck.err(
                        x.span(),
                        &format!("{field}.{name}"),
                        format!("{v} is outside 0..=90 degrees"),
                    ))
                }
            }
        };
        let cone = match &lf.direction {
            None => {
                if let Some(a) = lf.inner_angle.as_ref().or(lf.outer_angle.as_ref()) {
                    return Err(ck.err(
                        a.span(),
                        &field,
                        "cone angles belong to a spot light: give its direction",
                    ));
                }
                None
            }
            Some(d) => {
                let axis = ck.vec3(d, &format!("{field}.direction"))?;
                if !(axis.length() > 0.0) {
                    return Err(ck.err(d.span(), &format!("{field}.direction"), "is zero"));
                }
                let inner = angle(&lf.inner_angle, "inner_angle", 0.0)?;
                let outer = angle(&lf.outer_angle, "outer_angle", 45.0)?;
                if !(inner < outer) {
                    return Err(ck.err(
                        l.span(),
                        &field,
                        format!("inner_angle {inner} must be below outer_angle {outer}"),
                    ));
                }
                Some((axis, inner.to_radians(), outer.to_radians()))
            }
        };
        tables.lights.push(super::light_table::punctual_light(
            position,
            intensity.to_array(),
            cone,
        ));
    }

    let mut notes = Vec::new();
    for (i, g) in file.gltf.iter().enumerate() {
        let gf = g.get_ref();
        let field = format!("gltf[{i}]");
        let gltf_path = base_dir.join(gf.file.get_ref());
        if !gltf_path.is_file() {
            return Err(ck.err(
                gf.file.span(),
                &format!("{field}.file"),
                format!("glTF file {} does not exist", gltf_path.display()),
            ));
        }
        let transform = if transform_fields!(gf).is_given() {
            Some(parse_transform(&ck, &field, &transform_fields!(gf))?)
        } else {
            None
        };
        super::gltf_scene::include(&mut tables, &gltf_path, transform.as_ref(), &mut notes)?;
    }

    let (background, environment) = match &file.background {
        Some(b) => background(&ck, b, base_dir)?,
        None => (Vec3::ZERO, None),
    };
    let mut scene = tables.finish(
        path.display().to_string(),
        camera,
        render,
        background,
        environment,
    );
    scene.notes = notes;
    Ok(scene)
}

/// The `[background]` table: a uniform radiance, or an environment map with its scale and
/// rotation (exactly one of the two).
fn background(
    ck: &Checker,
    b: &BackgroundFile,
    base_dir: &Path,
) -> Result<(Vec3, Option<EnvironmentMap>), SceneError> {
    match (&b.radiance, &b.map) {
        (Some(r), None) => {
            if let Some(s) = b.scale.as_ref().or(b.rotation.as_ref()) {
                return Err(ck.err(
                    s.span(),
                    "background",
                    "scale and rotation belong to a map, not to a uniform radiance",
                ));
            }
            Ok((ck.color(r, "background.radiance", None)?, None))
        }
        (None, Some(m)) => {
            let map_path = base_dir.join(m.get_ref());
            if !map_path.is_file() {
                return Err(ck.err(
                    m.span(),
                    "background.map",
                    format!("map file {} does not exist", map_path.display()),
                ));
            }
            let mut map = EnvironmentMap::load(&map_path, "background.map")?;
            if let Some(s) = &b.scale {
                let k = *s.get_ref();
                if !(k >= 0.0 && k.is_finite()) {
                    return Err(ck.err(
                        s.span(),
                        "background.scale",
                        format!("{k} must be a non-negative finite number"),
                    ));
                }
                map.scale = k;
            }
            if let Some(r) = &b.rotation {
                let deg = *r.get_ref();
                if !deg.is_finite() {
                    return Err(ck.err(r.span(), "background.rotation", "is not finite"));
                }
                map.rotation_degrees = deg;
            }
            Ok((Vec3::ZERO, Some(map)))
        }
        (Some(_), Some(m)) => Err(ck.err(
            m.span(),
            "background",
            "gives both radiance and map: choose one",
        )),
        (None, None) => Err(SceneError::new(
            ck.path,
            None,
            "background",
            "needs radiance or map",
        )),
    }
}
