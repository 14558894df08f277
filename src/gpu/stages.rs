//! A stage on the GPU, built from its descriptor ([`crate::shader::Stage`]): the composed
//! shader module and, per pipeline, explicit bind group layouts made from the bindings the
//! descriptor says it uses — one compute pipeline per entry point, or one drawing pipeline
//! binding every binding. Bind groups are filled from the buffers of a whole group in binding
//! order; each pipeline takes the ones it uses.

use std::sync::OnceLock;

use crate::gpu::device::Gpu;
use crate::shader::{compose_with, Binding, BindingKind, ShaderOptions, Stage, StageKind, StandIn, WgslFile};

/// The layouts of one pipeline of a stage.
pub struct PipelineLayout {
    /// The entry point (compute), or None for the drawing pipeline.
    pub entry: Option<&'static str>,
    pub groups: Vec<wgpu::BindGroupLayout>,
    pub layout: wgpu::PipelineLayout,
}

pub struct GpuStage {
    pub stage: &'static Stage,
    /// One module per WGSL file of the stage, with the entry points it holds (created when a
    /// pipeline first needs it).
    modules: Vec<(WgslFile, OnceLock<wgpu::ShaderModule>)>,
    /// What the generated modules are composed for (the device's, or another way of drawing the
    /// eyes).
    options: ShaderOptions,
    pub layouts: Vec<PipelineLayout>,
}

fn layout_entry(b: &Binding, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: b.binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: match b.kind {
                BindingKind::Uniform => wgpu::BufferBindingType::Uniform,
                BindingKind::Storage => wgpu::BufferBindingType::Storage { read_only: true },
                BindingKind::StorageReadWrite => wgpu::BufferBindingType::Storage { read_only: false },
            },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A stage file's module, composed for `options` with `stand_ins`.
fn create_module(gpu: &Gpu, file: &WgslFile, options: ShaderOptions, stand_ins: &[StandIn]) -> wgpu::ShaderModule {
    gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&file.path),
        source: wgpu::ShaderSource::Wgsl(compose_with(file, options, stand_ins).into()),
    })
}

impl GpuStage {
    pub fn new(gpu: &Gpu, stage: &'static Stage) -> GpuStage {
        GpuStage::with_options(gpu, stage, gpu.shader_options())
    }

    /// The same composed for `options` instead of the device's.
    pub fn with_options(gpu: &Gpu, stage: &'static Stage, options: ShaderOptions) -> GpuStage {
        let device = &gpu.device;
        let modules = stage.files().into_iter().map(|file| (file, OnceLock::new())).collect();
        let (visibility, pipelines): (_, Vec<Option<&'static str>>) = match stage.kind {
            StageKind::Compute => {
                (wgpu::ShaderStages::COMPUTE, stage.entry_points.iter().map(|e| Some(e.name)).collect())
            }
            StageKind::Draw => (wgpu::ShaderStages::VERTEX_FRAGMENT, vec![None]),
        };
        let layouts = pipelines
            .into_iter()
            .map(|entry| {
                let groups: Vec<wgpu::BindGroupLayout> = (0..stage.group_count())
                    .map(|g| {
                        let entries: Vec<wgpu::BindGroupLayoutEntry> = stage
                            .group(g)
                            .filter(|b| stage.binds(entry, b))
                            .map(|b| layout_entry(b, visibility))
                            .collect();
                        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                            label: Some(&format!("{} {} group {g}", stage.name, entry.unwrap_or("draw"))),
                            entries: &entries,
                        })
                    })
                    .collect();
                let refs: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(Some).collect();
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(stage.name),
                    bind_group_layouts: &refs,
                    immediate_size: 0,
                });
                PipelineLayout { entry, groups, layout }
            })
            .collect();
        GpuStage { stage, modules, options, layouts }
    }

    /// The module that holds `entry` (None: the drawing pipeline's, the stage's one file).
    pub fn module(&self, gpu: &Gpu, entry: Option<&str>) -> &wgpu::ShaderModule {
        let holds = |(file, _): &&(WgslFile, OnceLock<wgpu::ShaderModule>)| {
            entry.is_none_or(|e| file.entry_points.contains(&e))
        };
        let (file, module) = self
            .modules
            .iter()
            .find(holds)
            .unwrap_or_else(|| panic!("{} has no entry point {entry:?}", self.stage.name));
        module.get_or_init(|| create_module(gpu, file, self.options, &[]))
    }

    fn pipeline_layout(&self, entry: Option<&str>) -> &PipelineLayout {
        self.layouts
            .iter()
            .find(|l| l.entry == entry)
            .unwrap_or_else(|| panic!("{} has no pipeline {entry:?}", self.stage.name))
    }

    /// The layout of the drawing pipeline.
    pub fn draw_layout(&self) -> &wgpu::PipelineLayout {
        &self.pipeline_layout(None).layout
    }

    /// The compute pipeline of one entry point.
    pub fn compute(&self, gpu: &Gpu, entry: &str) -> wgpu::ComputePipeline {
        self.compute_with(gpu, entry, &[])
    }

    /// The same with pipeline-overridable constants set (WGSL `override`).
    pub fn compute_with(&self, gpu: &Gpu, entry: &str, constants: &[(&str, f64)]) -> wgpu::ComputePipeline {
        self.compute_in(gpu, self.module(gpu, Some(entry)), entry, constants)
    }

    /// The same from the entry point's file composed with stand-ins in place of modules
    /// ([`crate::shader::STAND_INS`]).
    pub fn compute_standing_in(
        &self,
        gpu: &Gpu,
        entry: &str,
        constants: &[(&str, f64)],
        stand_ins: &[StandIn],
    ) -> wgpu::ComputePipeline {
        if stand_ins.is_empty() {
            return self.compute_with(gpu, entry, constants);
        }
        let module = create_module(gpu, &self.stage.file_of(Some(entry)), self.options, stand_ins);
        self.compute_in(gpu, &module, entry, constants)
    }

    fn compute_in(
        &self,
        gpu: &Gpu,
        module: &wgpu::ShaderModule,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> wgpu::ComputePipeline {
        gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&self.pipeline_layout(Some(entry)).layout),
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            cache: gpu.pipeline_cache(),
        })
    }

    /// A bind group of `group` for a pipeline (`entry`, or None for the drawing pipeline), from
    /// one buffer per binding of the whole group, in binding order; the pipeline's own bindings
    /// are taken from them.
    pub fn bind_group(&self, gpu: &Gpu, entry: Option<&str>, group: u32, buffers: &[&wgpu::Buffer]) -> wgpu::BindGroup {
        let whole: Vec<wgpu::BufferBinding> = buffers.iter().map(|b| b.as_entire_buffer_binding()).collect();
        self.bind_group_ranges(gpu, entry, group, &whole)
    }

    /// The same with buffer ranges (a binding of part of a buffer larger than one binding holds).
    pub fn bind_group_ranges(
        &self,
        gpu: &Gpu,
        entry: Option<&str>,
        group: u32,
        buffers: &[wgpu::BufferBinding],
    ) -> wgpu::BindGroup {
        let bindings: Vec<&Binding> = self.stage.group(group).collect();
        assert_eq!(bindings.len(), buffers.len(), "{} group {group}: one buffer per binding", self.stage.name);
        let entries: Vec<wgpu::BindGroupEntry> = bindings
            .iter()
            .zip(buffers)
            .filter(|(b, _)| self.stage.binds(entry, b))
            .map(|(b, buffer)| wgpu::BindGroupEntry {
                binding: b.binding,
                resource: wgpu::BindingResource::Buffer(buffer.clone()),
            })
            .collect();
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.stage.name),
            layout: &self.pipeline_layout(entry).groups[group as usize],
            entries: &entries,
        })
    }
}
