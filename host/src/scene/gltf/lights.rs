//! A glTF node's `KHR_lights_punctual` light: point, spot or directional, converted from the
//! file's photometric units into twinpath's radiometric ones (`super::LightUnits`).

use super::import::Import;
use crate::scene::SceneError;
use glam::{DMat4, DVec4, Vec3};

impl Import<'_> {
    /// Adds `KHR_lights_punctual` light `light` of `node` at `world`: a point or spot light at
    /// the node's origin, a spot pointing down the node's -z, of radiant intensity colour x
    /// intensity in the import's `LightUnits`; `range` is ignored (physical falloff). A
    /// directional light shines down the node's -z, its irradiance colour x intensity in those
    /// units.
    pub(super) fn add_light(
        &mut self,
        node: &gltf::Node,
        light: &gltf::khr_lights_punctual::Light,
        world: DMat4,
    ) -> Result<(), SceneError> {
        use gltf::khr_lights_punctual::Kind;
        let field = format!("KHR_lights_punctual.lights[{}]", light.index());
        let path = self.path.clone();
        let err = |msg: String| SceneError::new(&path, None, field.clone(), msg);
        let directional = matches!(light.kind(), Kind::Directional);
        let intensity = Vec3::from(light.color())
            * self.light_units.radiometric(light.intensity(), directional);
        if !(intensity.is_finite() && intensity.min_element() >= 0.0) {
            return Err(err(format!(
                "colour x intensity {:?} must be finite and >= 0",
                intensity.to_array()
            )));
        }
        if light.range().is_some() {
            self.note(format!(
                "{field}: range ignored (light falls off as 1/d^2 everywhere)"
            ));
        }
        let position = (world * DVec4::W).truncate();
        let axis = (world * DVec4::new(0.0, 0.0, -1.0, 0.0)).truncate();
        if !(position.is_finite()
            && position.abs().max_element() <= crate::scene::limits::MAX_COORDINATE as f64)
        {
            return Err(err(format!(
                "nodes[{}] places it at {position}, out of range",
                node.index()
            )));
        }
        let cone = match light.kind() {
            Kind::Directional => {
                if !(axis.length() > 0.0 && axis.is_finite()) {
                    return Err(err(format!(
                        "nodes[{}] gives the directional light no direction",
                        node.index()
                    )));
                }
                self.tables
                    .lights
                    .push(crate::scene::light_table::directional_light(
                        axis.as_vec3(),
                        intensity.to_array(),
                    ));
                return Ok(());
            }
            Kind::Point => None,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                if !(0.0 <= inner_cone_angle
                    && inner_cone_angle < outer_cone_angle
                    && outer_cone_angle <= std::f32::consts::FRAC_PI_2)
                    || !(axis.length() > 0.0)
                {
                    return Err(err(format!(
                        "spot cone angles {inner_cone_angle}, {outer_cone_angle} must satisfy \
                         0 <= inner < outer <= pi/2"
                    )));
                }
                Some((
                    axis.normalize().as_vec3(),
                    inner_cone_angle,
                    outer_cone_angle,
                ))
            }
        };
        self.tables
            .lights
            .push(crate::scene::light_table::punctual_light(
                position.as_vec3(),
                intensity.to_array(),
                cone,
            ));
        Ok(())
    }
}
