//! A scene uploaded to the GPU: vertices, indices, the material table and the per-object
//! factor on L; a level-of-detail selection swaps only the index buffer and the factors.

use std::sync::Mutex;

use glam::{Mat4, Vec3};

use crate::core::detail::lod::LodSelection;
use crate::core::scenes::bvh::SceneBvh;
use crate::core::scenes::scene::{object_spheres, Scene};
use crate::core::scenes::shared_edges::{shared_edges_of, welded_points, SharedEdges};
use crate::core::settings::RenderSettings;
use crate::core::shading::environment::PreparedEnvironment;
use crate::core::shading::light::{gpu_lights, Light, LightingParams, SceneLighting};
use crate::core::shading::shadow::{GpuShadowMap, MAX_SHADOW_MAPS};
use crate::core::shading::texture::MaterialTable;
use crate::encoding::constants::TRACE_STACK;
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;

/// One object's triangles and bounding sphere (scene coordinates), for the slit renderer's culling.
#[derive(Clone, Copy, Debug)]
pub struct ObjectRange {
    pub first_triangle: u32,
    pub triangle_count: u32,
    pub center: Vec3,
    pub radius: f32,
}

/// The scene's buffers of the drawing stages' and the ray tracer's group 1 (shaders/shared/
/// surface.wgsl), the shadow maps' aside: the material table (materials, mip levels, texels),
/// the lights and the frame's lighting (written per frame), the environment's texels.
#[derive(Clone)]
pub struct MaterialBuffers {
    pub materials: wgpu::Buffer,
    pub mip_levels: wgpu::Buffer,
    pub texels: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub lighting: wgpu::Buffer,
    pub environment: wgpu::Buffer,
}

impl MaterialBuffers {
    /// The material table and the scene's lights uploaded (the lighting is written per frame).
    fn upload(gpu: &Gpu, table: &MaterialTable, lights: &[Light]) -> MaterialBuffers {
        let storage = |label: &str, bytes: &[u8]| gpu.init_buffer(label, bytes, wgpu::BufferUsages::STORAGE);
        let written = |usage| usage | wgpu::BufferUsages::COPY_DST;
        let environment: &[u32] = if table.environment.is_empty() { &[0] } else { &table.environment };
        MaterialBuffers {
            materials: storage("materials", bytemuck::cast_slice(&table.materials)),
            mip_levels: storage("mip levels", bytemuck::cast_slice(&table.mips)),
            texels: storage("texels", bytemuck::cast_slice(&table.texels)),
            lights: gpu.init_buffer(
                "lights",
                bytemuck::cast_slice(&gpu_lights(lights, Mat4::IDENTITY)),
                written(wgpu::BufferUsages::STORAGE),
            ),
            lighting: gpu.init_buffer(
                "lighting",
                bytemuck::bytes_of(&LightingParams::default()),
                written(wgpu::BufferUsages::UNIFORM),
            ),
            environment: storage("environment", bytemuck::cast_slice(environment)),
        }
    }
}

pub struct GpuScene {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub triangle_count: u32,
    pub objects: Vec<ObjectRange>,
    /// What the drawing stages' and the ray tracer's group 1 binds of the scene.
    pub materials: MaterialBuffers,
    /// The environment that lights the scene's frames (its texels are in `materials.environment`), if any.
    pub environment: Option<std::sync::Arc<PreparedEnvironment>>,
    /// The scene's lights (scene frame), written into group 1 per frame.
    pub lights: Vec<Light>,
    /// Whether its materials are physically based (a glTF file's: `Scene::physically_based`).
    pub physically_based: bool,
    /// What the packing of the textures had to say (levels dropped to fit the budget).
    pub warnings: Vec<String>,
    /// Per object: the factor on L of the adaptive subdivision (1; the level of detail sets it).
    pub object_edge_scale: wgpu::Buffer,
    /// The triangles' shared edges (`core::scenes::shared_edges`): three edge numbers per triangle, and
    /// two bits per edge that the subdivision's `active_cuts` and `ring_cuts` set each frame
    /// (`cut_edges`, in the frame's `SubdivisionBuffers`: `cut_edge_words` words).
    pub triangle_edges: wgpu::Buffer,
    pub cut_edge_words: u32,
    /// Each vertex's welded point, for the edges of a level-of-detail selection.
    pub points: std::sync::Arc<Vec<u32>>,
    /// Whether some material is textured, not opaque or single-sided (else the drawing stages
    /// use their plain pipelines).
    pub needs_materials: bool,
    /// Whether any material can discard a fragment (`MaterialTable::discards`).
    pub discards: bool,
    /// Whether any material has glTF texture maps (metallic-roughness, normal, occlusion, emissive).
    pub has_maps: bool,
    /// Every material is single-sided: the drawing pipelines cull back faces.
    pub cull_back_faces: bool,
    /// Some material mirrors or transmits light (the ray tracer then runs its material code).
    pub has_optics: bool,
    /// The BVH the ray tracer walks (`--method trace`), once built ([`GpuScene::with_bvh`]).
    pub bvh: Option<GpuBvh>,
    /// The scene's bounding box (scene frame), which the shadow maps are fitted to.
    pub bounds: Option<(Vec3, Vec3)>,
    /// The frame's shadow maps (group 1's bindings 6 and 7), drawn when a frame needs them.
    pub shadows: Mutex<GpuShadows>,
    /// An animated scene's skinning tables, made on its first pose on the GPU (`gpu::skin`).
    pub rig: Option<GpuRig>,
}

/// A scene's BVH on the GPU ([`SceneBvh`]): nodes, the objects' chains of levels, and the
/// triangles (every level's, leaf by leaf).
pub struct GpuBvh {
    pub nodes: wgpu::Buffer,
    pub levels: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub node_count: usize,
    /// [`SceneBvh::original_root`], and the chains' first step ([`SceneBvh::first_step`]).
    pub original_root: u32,
    pub first_step: f32,
}

impl GpuScene {
    /// Validates and uploads a scene; fails with a clear message if it cannot fit the device.
    pub fn upload(gpu: &Gpu, scene: &Scene) -> Result<GpuScene> {
        scene.validate()?;
        check_fits(gpu, scene)?;
        let max = gpu.max_binding();
        gpu.scoped(&format!("uploading {}", scene.name), || {
            // COPY_DST: an animated scene's frames write their poses in; COPY_SRC: the skin
            // stage's twin test reads them back.
            let vertices = gpu.init_buffer(
                "scene vertices",
                bytemuck::cast_slice(&scene.vertices),
                wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::VERTEX
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
            );
            let indices = gpu.init_buffer(
                "scene indices",
                bytemuck::cast_slice(&scene.indices),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX,
            );
            let objects = scene
                .objects
                .iter()
                .zip(object_spheres(scene))
                .map(|(o, (center, radius))| ObjectRange {
                    first_triangle: o.first_triangle,
                    triangle_count: o.triangle_count,
                    center,
                    radius,
                })
                .collect();
            // Textures get at most a quarter of the device's largest binding (max/16 texels of 4
            // bytes; levels are dropped, largest first, with a warning).
            let table = scene.material_table((max / 16) as usize);
            let materials = MaterialBuffers::upload(gpu, &table, &scene.lights);
            let storage = |label: &str, bytes: &[u8]| gpu.init_buffer(label, bytes, wgpu::BufferUsages::STORAGE);
            let ones = vec![1.0f32; scene.objects.len().max(1)];
            // The glTF BRDF reads the materials' factors.
            let needs_materials = table.needs_materials() || !scene.lights.is_empty() || scene.environment.is_some();
            let has_optics = table.has_optics();
            let discards = table.discards();
            let has_maps = table.materials.iter().any(|m| m.has_maps());
            let cull_back_faces = table.all_single_sided(scene.vertices.iter().map(|v| v.material));
            let points = welded_points(&scene.vertices);
            let (triangle_edges, cut_edge_words) = edge_buffers(gpu, &shared_edges_of(&points, &scene.indices));
            Ok(GpuScene {
                triangle_edges,
                cut_edge_words,
                points: std::sync::Arc::new(points),
                vertices,
                indices,
                triangle_count: scene.triangle_count() as u32,
                objects,
                materials,
                warnings: table.warnings,
                object_edge_scale: storage("object edge scale", bytemuck::cast_slice(&ones)),
                needs_materials,
                discards,
                has_maps,
                cull_back_faces,
                has_optics,
                bvh: None,
                bounds: scene.bounds(),
                shadows: Mutex::new(GpuShadows::new(gpu)),
                rig: None,
                lights: scene.lights.clone(),
                physically_based: scene.physically_based,
                environment: scene
                    .environment
                    .as_ref()
                    .map(|e| std::sync::Arc::new(PreparedEnvironment { texels: Vec::new(), ..(**e).clone() })),
            })
        })
    }

    /// Takes a new pose of the same scene (`core::scenes::animation::Rig::pose`): its vertices written
    /// over the uploaded ones (the only upload), its lights and bounds; the shadow maps are
    /// drawn again.
    pub fn update_pose(&mut self, gpu: &Gpu, scene: &Scene) -> Result<()> {
        if scene.vertices.len() as u64 * std::mem::size_of::<crate::core::scenes::scene::SceneVertex>() as u64
            != self.vertices.size()
        {
            return Err(Error::scene(&scene.name, "a pose must keep the scene's vertices"));
        }
        scene.validate()?;
        gpu.queue.write_buffer(&self.vertices, 0, bytemuck::cast_slice(&scene.vertices));
        self.lights = scene.lights.clone();
        self.bounds = scene.bounds();
        self.shadows.lock().unwrap_or_else(|e| e.into_inner()).drawn.clear();
        Ok(())
    }

    /// Whether a frame with `settings` is lit by the glTF BRDF.
    pub fn pbr(&self, settings: &RenderSettings) -> bool {
        let scene = SceneLighting { lights: self.lights.len(), physically_based: self.physically_based };
        settings.lighting_params(scene, self.environment.as_deref()).pbr != 0
    }

    /// Whether a frame with `settings` shows the environment as its background (one the user
    /// gave, lit by the glTF BRDF).
    pub fn shows_environment(&self, settings: &RenderSettings) -> bool {
        self.pbr(settings) && self.environment.as_ref().is_some_and(|e| e.background)
    }

    /// Writes a frame's lights (in the viewer frame of `settings`) and lighting into group 1;
    /// returns the frame's shadow maps (drawn by the renderer).
    pub fn write_lighting(&self, gpu: &Gpu, settings: &RenderSettings) -> Vec<GpuShadowMap> {
        let (lights, params, maps) =
            settings.shadowed_lighting(&self.lights, self.physically_based, self.environment.as_deref(), self.bounds);
        gpu.queue.write_buffer(&self.materials.lights, 0, bytemuck::cast_slice(&lights));
        gpu.queue.write_buffer(&self.materials.lighting, 0, bytemuck::bytes_of(&params));
        maps
    }

    /// Whether a frame with `settings` reads shadow maps (the drawing pipelines' `SHADOW_MAPS`).
    pub fn shadow_maps(&self, settings: &RenderSettings) -> bool {
        settings.uses_shadow_maps(&self.lights, self.pbr(settings))
    }

    /// Group 1's buffers in binding order: the material table, lights, lighting, environment,
    /// and the shadow maps' table and depths of `shadows` (the scene's, locked).
    pub fn group1(&self, shadows: &GpuShadows) -> [wgpu::Buffer; 8] {
        let m = &self.materials;
        [&m.materials, &m.mip_levels, &m.texels, &m.lights, &m.lighting, &m.environment, &shadows.maps, &shadows.depths]
            .map(Clone::clone)
    }

    /// Group 1's buffers as a frame binds them.
    pub fn material_buffers(&self) -> [wgpu::Buffer; 8] {
        self.group1(&self.shadows.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// The same scene with its BVH built (on the CPU, one level per object) and uploaded, for
    /// the ray tracer. Fails with one line if the tree is deeper than the traversal's stack or
    /// too big for the device.
    pub fn with_bvh(self, gpu: &Gpu, scene: &Scene) -> Result<GpuScene> {
        self.with_built_bvh(gpu, &scene.name, &SceneBvh::of_scene(scene))
    }

    /// The same scene with `bvh` (built over its vertices, e.g. with a level-of-detail chain
    /// per object) uploaded; `name` names the scene in errors.
    pub fn with_built_bvh(mut self, gpu: &Gpu, name: &str, bvh: &SceneBvh) -> Result<GpuScene> {
        self.set_bvh(gpu, name, bvh)?;
        Ok(self)
    }

    /// The BVH of a new pose of the scene (a sequence's frame), built and uploaded anew.
    pub fn rebuild_bvh(&mut self, gpu: &Gpu, scene: &Scene) -> Result<()> {
        self.set_bvh(gpu, &scene.name, &SceneBvh::of_scene(scene))
    }

    fn set_bvh(&mut self, gpu: &Gpu, name: &str, bvh: &SceneBvh) -> Result<()> {
        let depth = bvh.depth();
        if depth > TRACE_STACK {
            return Err(Error::scene(
                name,
                format!("its BVH is {depth} levels deep, more than the ray tracer's stack of {TRACE_STACK}"),
            ));
        }
        let bytes = std::mem::size_of_val(bvh.nodes.as_slice()).max(4 * bvh.indices.len()) as u64;
        if bytes > gpu.max_binding() {
            return Err(Error::scene(
                name,
                format!(
                    "its BVH ({} MiB) is larger than this GPU binds ({} MiB)",
                    bytes >> 20,
                    gpu.max_binding() >> 20
                ),
            ));
        }
        self.bvh = Some(gpu.scoped(&format!("uploading the BVH of {name}"), || {
            let storage = |label: &str, bytes: &[u8]| gpu.init_buffer(label, bytes, wgpu::BufferUsages::STORAGE);
            // An empty chain table still needs a binding.
            let levels: &[u8] = if bvh.levels.is_empty() { &[0; 8] } else { bytemuck::cast_slice(&bvh.levels) };
            Ok(GpuBvh {
                nodes: storage("bvh nodes", bytemuck::cast_slice(&bvh.nodes)),
                levels: storage("bvh levels", levels),
                indices: storage("bvh triangles", bytemuck::cast_slice(&bvh.indices)),
                node_count: bvh.nodes.len(),
                original_root: bvh.original_root,
                first_step: bvh.first_step,
            })
        })?);
        Ok(())
    }

    /// The scene as a level-of-detail selection draws it: the same vertices and materials, the
    /// selection's triangles (a new index buffer, the only upload) and per-object factors on L.
    pub fn with_lod(&self, gpu: &Gpu, selection: &LodSelection) -> GpuScene {
        let scales = selection.edge_scales();
        let (triangle_edges, cut_edge_words) = edge_buffers(gpu, &shared_edges_of(&self.points, &selection.indices));
        GpuScene {
            triangle_edges,
            cut_edge_words,
            points: self.points.clone(),
            vertices: self.vertices.clone(),
            indices: gpu.init_buffer(
                "lod indices",
                bytemuck::cast_slice(&selection.indices),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX,
            ),
            triangle_count: (selection.indices.len() / 3) as u32,
            objects: self
                .objects
                .iter()
                .zip(&selection.objects)
                .map(|(r, o)| ObjectRange { first_triangle: o.first_triangle, triangle_count: o.triangle_count, ..*r })
                .collect(),
            materials: self.materials.clone(),
            warnings: self.warnings.clone(),
            object_edge_scale: gpu.init_buffer(
                "object edge scale",
                bytemuck::cast_slice(&scales),
                wgpu::BufferUsages::STORAGE,
            ),
            needs_materials: self.needs_materials,
            discards: self.discards,
            has_maps: self.has_maps,
            cull_back_faces: self.cull_back_faces,
            has_optics: self.has_optics,
            // The BVH indexes the full scene's triangles: a selection has none (yet).
            bvh: None,
            bounds: self.bounds,
            shadows: Mutex::new(GpuShadows::new(gpu)),
            rig: None,
            lights: self.lights.clone(),
            physically_based: self.physically_based,
            environment: self.environment.clone(),
        }
    }
}

/// The subdivision's edge buffers for a scene's shared edges: their numbers per triangle, and
/// room for two bits per edge (`FrameCuts`).
/// The triangles' edge numbers, and the words of two bits per edge the frame's marks need.
fn edge_buffers(gpu: &Gpu, edges: &SharedEdges) -> (wgpu::Buffer, u32) {
    (
        gpu.init_buffer("triangle edges", bytemuck::cast_slice(&edges.ids), wgpu::BufferUsages::STORAGE),
        edges.bit_words(2),
    )
}

/// A scene's shadow maps on the GPU: the maps' table (group 1 binding 6, [`MAX_SHADOW_MAPS`]
/// entries) and their depths (binding 7), the depth textures they are drawn into, and what the
/// depths hold now.
pub struct GpuShadows {
    pub maps: wgpu::Buffer,
    pub depths: wgpu::Buffer,
    pub(crate) textures: Vec<wgpu::Texture>,
    /// Each drawn map's projection (scene frame → clip) and side; empty: none drawn.
    pub(crate) drawn: Vec<([[f32; 4]; 4], u32)>,
}

impl GpuShadows {
    pub fn new(gpu: &Gpu) -> GpuShadows {
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        GpuShadows {
            maps: gpu.init_buffer(
                "shadow maps",
                bytemuck::cast_slice(&[GpuShadowMap::default(); MAX_SHADOW_MAPS]),
                usage,
            ),
            depths: gpu.init_buffer("shadow depths", &[0; 4], usage),
            textures: Vec::new(),
            drawn: Vec::new(),
        }
    }
}

/// A rig's tables on the GPU: uploaded once (sources, offsets), written per frame (instances,
/// joints, weights), and the mesh-frame boxes for the posed bounds.
pub struct GpuRig {
    pub(crate) data: crate::encoding::skin::SkinData,
    pub(crate) params: wgpu::Buffer,
    pub(crate) sources: wgpu::Buffer,
    pub(crate) deltas: wgpu::Buffer,
    pub(crate) instances: wgpu::Buffer,
    pub(crate) joints: wgpu::Buffer,
    pub(crate) weights: wgpu::Buffer,
}

/// Fails with one line where the scene's vertices or indices are more than one buffer binding
/// of this device holds.
fn check_fits(gpu: &Gpu, scene: &Scene) -> Result<()> {
    let vbytes = std::mem::size_of_val(scene.vertices.as_slice()) as u64;
    let ibytes = std::mem::size_of_val(scene.indices.as_slice()) as u64;
    let max = gpu.max_binding();
    if vbytes > max || ibytes > max {
        return Err(Error::scene(
            &scene.name,
            format!(
                "too big for this GPU: {} vertices ({} MiB) and {} triangles ({} MiB); one buffer may hold at most {} MiB",
                scene.vertices.len(),
                vbytes >> 20,
                scene.triangle_count(),
                ibytes >> 20,
                max >> 20
            ),
        ));
    }
    Ok(())
}
