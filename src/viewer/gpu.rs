//! The GPU: an adapter and device, with errors captured instead of panics.

use super::ViewerError;
use std::sync::{Arc, Mutex};
use wgpu::util::DeviceExt;

/// An adapter, its device and queue, and the errors the device reported.
pub struct Gpu {
    /// The instance (kept for window surfaces).
    pub instance: wgpu::Instance,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    errors: Arc<Mutex<Vec<String>>>,
}

impl Gpu {
    /// A GPU without a display (offscreen rendering); a software one (lavapipe, llvmpipe)
    /// where no other is found.
    pub fn headless() -> Result<Gpu, ViewerError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Gpu::with_instance(instance, None)
    }

    /// A GPU for `instance` that can present to `surface`, if given.
    pub fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Gpu, ViewerError> {
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: surface,
            ..Default::default()
        }))
        .map_err(|e| ViewerError::NoAdapter(e.to_string()))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("halo4d-view"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| ViewerError::NoAdapter(format!("the adapter gave no device: {e}")))?;
        let errors: Arc<Mutex<Vec<String>>> = Arc::default();
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut list) = sink.lock() {
                list.push(e.to_string());
            }
        }));
        let sink = errors.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut list) = sink.lock() {
                list.push(format!("device lost ({reason:?}): {message}"));
            }
        });
        Ok(Gpu {
            instance,
            adapter,
            device,
            queue,
            errors,
        })
    }

    /// The adapter's name and backend, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)`.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
    }

    /// The device's limits.
    pub fn limits(&self) -> wgpu::Limits {
        self.device.limits()
    }

    /// Waits for the queue to finish, then reports any error the device raised since the
    /// last call.
    pub fn finish(&self) -> Result<(), ViewerError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| ViewerError::Gpu(e.to_string()))?;
        self.take_errors()
    }

    /// Any error the device raised since the last call.
    pub fn take_errors(&self) -> Result<(), ViewerError> {
        let mut list = self
            .errors
            .lock()
            .map_err(|_| ViewerError::Gpu("the error list was poisoned".into()))?;
        if list.is_empty() {
            return Ok(());
        }
        let message = list.join("; ");
        list.clear();
        Err(ViewerError::Gpu(message))
    }

    /// A buffer of `bytes` for `usage`, or a clear error when it exceeds the device's
    /// limits (`what` names it).
    pub(crate) fn buffer(
        &self,
        what: &str,
        bytes: &[u8],
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, ViewerError> {
        self.fits(what, bytes.len() as u64, usage)?;
        // A zero-sized binding is invalid: an empty array gets one zero element.
        let zeros = [0u8; 16];
        Ok(self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(what),
                contents: if bytes.is_empty() { &zeros } else { bytes },
                usage: usage | wgpu::BufferUsages::COPY_DST,
            }))
    }

    /// Whether a buffer of `size` bytes for `usage` fits the device's limits.
    pub(crate) fn fits(
        &self,
        what: &str,
        size: u64,
        usage: wgpu::BufferUsages,
    ) -> Result<(), ViewerError> {
        let limits = self.limits();
        let mut limit = (limits.max_buffer_size, "max_buffer_size");
        if usage.contains(wgpu::BufferUsages::STORAGE) {
            limit = limit.min((
                limits.max_storage_buffer_binding_size,
                "max_storage_buffer_binding_size",
            ));
        }
        if size > limit.0 {
            return Err(ViewerError::TooLarge {
                what: format!("{what} (bytes)"),
                count: size,
                limit: limit.0,
                why: format!("this GPU's {}", limit.1),
            });
        }
        Ok(())
    }

    /// Reads a 2D texture of 4-byte texels back: `width * height` texels, row-major.
    pub(crate) fn read_texture(
        &self,
        texture: &wgpu::Texture,
    ) -> Result<Vec<[u8; 4]>, ViewerError> {
        let (w, h) = (texture.width(), texture.height());
        let row = (4 * w).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: u64::from(row) * u64::from(h),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([encoder.finish()]);
        let data = self.map_read(&buffer)?;
        let mut out = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            let line = &data[y * row as usize..][..4 * w as usize];
            out.extend(line.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
        }
        Ok(out)
    }

    /// Reads the first `size` bytes of each of `buffers` (made with `COPY_SRC`) back, in
    /// one copy and one wait.
    pub(crate) fn read_buffers(
        &self,
        buffers: &[(&wgpu::Buffer, u64)],
    ) -> Result<Vec<Vec<u8>>, ViewerError> {
        let total: u64 = buffers.iter().map(|b| b.1.next_multiple_of(4)).sum();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: total.max(4),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let mut at = 0;
        for &(buffer, size) in buffers {
            let size = size.next_multiple_of(4);
            encoder.copy_buffer_to_buffer(buffer, 0, &staging, at, size);
            at += size;
        }
        self.queue.submit([encoder.finish()]);
        let data = self.map_read(&staging)?;
        let mut at = 0usize;
        Ok(buffers
            .iter()
            .map(|&(_, size)| {
                let part = data[at..at + size as usize].to_vec();
                at += size.next_multiple_of(4) as usize;
                part
            })
            .collect())
    }

    /// Waits for the GPU and maps `buffer` (made with `MAP_READ`): its bytes.
    fn map_read(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>, ViewerError> {
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.finish()?;
        rx.recv()
            .map_err(|e| ViewerError::Gpu(e.to_string()))?
            .map_err(|e| ViewerError::Gpu(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| ViewerError::Gpu(e.to_string()))?
            .to_vec();
        buffer.unmap();
        Ok(data)
    }
}

/// The compute pipeline of `module`'s entry point `entry`, its bind group layout taken from
/// the shader.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}
