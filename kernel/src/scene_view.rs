//! The scene as the kernel reads it: the render's parameters and every table, borrowed from
//! the backend's buffers (the GPU's storage buffers, the CPU renderer's vectors) and passed
//! once, as one value, to whatever reads the scene.

use crate::medium::Medium;
use crate::scene::{Instance, Light, Material, RenderParams, ShadingTriangle};

/// The tables of `crate::scene` a path reads, and the render's parameters. Geometry (spheres,
/// triangles) is not here: the kernel meets it only through `path::Tracer`.
#[derive(Clone, Copy)]
pub struct SceneView<'a> {
    pub params: &'a RenderParams,
    pub materials: &'a [Material],
    pub lights: &'a [Light],
    /// The environment map's table (`crate::environment`; one number when there is no map).
    pub environment: &'a [f32],
    /// The shading table (`ShadingTriangle`s: vertex normals, texture coordinates, frames).
    pub shading: &'a [ShadingTriangle],
    /// The texture table (`crate::texture`).
    pub textures: &'a [u32],
    pub instances: &'a [Instance],
    /// The media table (`crate::medium`; record 0 is vacuum).
    pub media: &'a [Medium],
    /// The grid table (`crate::density_grid`; one word when no medium has a grid).
    pub grids: &'a [u32],
    /// The split table: continuations at the first vertex per tile (`crate::split`; read only
    /// under `split_mode::TABLE`).
    pub splits: &'a [u32],
}
