//! Binary data of a glTF file: buffers (GLB chunk, `data:` URIs, files in the glTF file's
//! folder), buffer views and accessors, each range-checked before a byte is read.

use super::uri::{FileSource, UriSource, resolve_uri};
use super::{Ctx, LoadOptions, over_budget};
use crate::SceneError;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;
use std::borrow::Cow;
use std::path::Path;

/// One buffer's bytes, or why it has none: a buffer without `uri` that is not the GLB binary
/// chunk is valid as long as nothing reads it, so the problem is reported only when a buffer
/// view does.
pub(super) type BufferData<'a> = Result<Cow<'a, [u8]>, &'static str>;

/// Loads every buffer of the file (`glb`: the binary chunk of a GLB file, `None` for a
/// `.gltf` file); each is cut to its declared `byteLength` (of a file, only
/// that many bytes are read: the file may be longer, not shorter). The declared lengths count
/// against `LoadOptions::max_buffer_bytes` before each buffer is read; a buffer without data
/// (see [`BufferData`]) counts nothing.
pub(super) fn load_buffers<'a>(
    path: &Path,
    base_dir: &Path,
    files: FileSource<'_>,
    root: &gltf::json::Root,
    glb: Option<Option<&'a [u8]>>,
    options: &LoadOptions,
) -> Result<Vec<BufferData<'a>>, SceneError> {
    let glb_bin = glb.flatten();
    let mut out = Vec::with_capacity(root.buffers.len());
    let mut total = 0u64;
    for (i, buffer) in root.buffers.iter().enumerate() {
        let what = format!("buffer {i}");
        let declared = buffer.byte_length.0;
        let absent = match &buffer.uri {
            Some(_) => None,
            None if i == 0 && glb_bin.is_some() => None,
            None if i > 0 && glb.is_some() => Some("has no uri (only buffer 0 may use the GLB binary chunk)"),
            None => Some("has no uri and the file has no GLB binary chunk"),
        };
        if let Some(problem) = absent {
            out.push(Err(problem));
            continue;
        }
        total = total.saturating_add(declared);
        if total > options.max_buffer_bytes {
            let what = if i == 0 { what } else { format!("{what} (with the buffers before it)") };
            let limit = options.max_buffer_bytes;
            return Err(over_budget(path, what, total, "bytes of buffers", limit, "max_buffer_bytes"));
        }
        let data: Cow<'a, [u8]> = match &buffer.uri {
            Some(uri) => match resolve_uri(path, base_dir, files, &what, uri)? {
                UriSource::Bytes { bytes } => Cow::Owned(bytes),
                UriSource::File(file) => {
                    if file.size < declared {
                        return Err(SceneError::BadBuffer {
                            path: path.to_owned(),
                            buffer: i,
                            problem: format!(
                                "`{}` has {} bytes but its byteLength is {declared}",
                                file.path.display(),
                                file.size
                            ),
                        });
                    }
                    Cow::Owned(file.read_prefix(path, &what, declared)?)
                }
            },
            // Not `absent`: buffer 0 of a file with a GLB binary chunk.
            None => Cow::Borrowed(glb_bin.unwrap_or_default()),
        };
        if (data.len() as u64) < declared {
            return Err(SceneError::BadBuffer {
                path: path.to_owned(),
                buffer: i,
                problem: format!("has {} bytes but its byteLength is {declared}", data.len()),
            });
        }
        // `declared <= data.len()`, so it fits in usize.
        let data = match data {
            Cow::Borrowed(b) => Cow::Borrowed(&b[..declared as usize]),
            Cow::Owned(mut v) => {
                v.truncate(declared as usize);
                Cow::Owned(v)
            }
        };
        out.push(Ok(data));
    }
    Ok(out)
}

/// Name of a component type for messages.
fn component_name(c: ComponentType) -> &'static str {
    match c {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

/// Name of an accessor type for messages.
fn type_name(t: Type) -> &'static str {
    match t {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

/// Shape of one accessor after its type was checked.
#[derive(Clone, Copy)]
pub(super) struct Layout {
    /// Number of elements.
    pub(super) count: usize,
    components: usize,
    component: ComponentType,
    normalized: bool,
}

impl Layout {
    fn element_size(&self) -> usize {
        self.components * self.component.size()
    }
}

impl Ctx<'_> {
    /// The bytes of buffer view `view`, after checking that it lies inside its buffer.
    pub(super) fn view_bytes(&self, view: usize, what: &str) -> Result<&[u8], SceneError> {
        let v = self.lookup(&self.root.buffer_views, view, what, "buffer view")?;
        let buffer = v.buffer.value();
        let data = self.lookup(&self.buffers, buffer, &format!("buffer view {view}"), "buffer")?;
        let data = data.as_ref().map_err(|problem| SceneError::BadBuffer {
            path: self.path.to_owned(),
            buffer,
            problem: format!("{problem}, and buffer view {view} reads it"),
        })?;
        let offset = v.byte_offset.map_or(0, |o| o.0);
        let length = v.byte_length.0;
        match offset.checked_add(length) {
            Some(end) if end <= data.len() as u64 => Ok(&data[offset as usize..end as usize]),
            _ => Err(SceneError::ViewOutOfRange {
                path: self.path.to_owned(),
                view,
                offset,
                length,
                buffer,
                buffer_len: data.len() as u64,
            }),
        }
    }

    /// Checks accessor `index`'s type against `usage` and returns its shape.
    fn layout(
        &self,
        index: usize,
        what: &str,
        usage: &str,
        accept: &dyn Fn(Type, ComponentType, bool) -> bool,
        expected: &'static str,
    ) -> Result<Layout, SceneError> {
        let a = self.lookup(&self.root.accessors, index, what, "accessor")?;
        let wrong = |found: String| SceneError::AccessorType {
            path: self.path.to_owned(),
            accessor: index,
            usage: usage.to_owned(),
            found,
            expected,
        };
        let (Checked::Valid(ty), Checked::Valid(ct)) = (&a.type_, &a.component_type) else {
            return Err(wrong("of an invalid type or component type".into()));
        };
        let (ty, ct) = (*ty, ct.0);
        if !accept(ty, ct, a.normalized) {
            let norm = if a.normalized { "normalized " } else { "" };
            return Err(wrong(format!("{} of {norm}{}", type_name(ty), component_name(ct))));
        }
        let count = usize::try_from(a.count.0).map_err(|_| self.bad_accessor(index, "count is too large"))?;
        Ok(Layout { count, components: ty.multiplicity(), component: ct, normalized: a.normalized })
    }

    fn bad_accessor(&self, accessor: usize, problem: &str) -> SceneError {
        SceneError::BadAccessor { path: self.path.to_owned(), accessor, problem: problem.to_owned() }
    }

    /// The accessor's elements, tightly packed (`count * element_size` bytes), with sparse
    /// substitutions applied. Every range is checked before reading.
    fn packed(&self, index: usize, layout: Layout) -> Result<Vec<u8>, SceneError> {
        let a = &self.root.accessors[index]; // `layout` checked the index
        let elem = layout.element_size() as u64;
        let count = layout.count as u64;
        let total = count.saturating_mul(elem);
        let limit = self.options.max_accessor_bytes;
        if total > limit {
            let what = format!("accessor {index}");
            return Err(over_budget(self.path, what, total, "bytes", limit, "max_accessor_bytes"));
        }
        let mut out;
        if let Some(view_index) = a.buffer_view {
            let view_index = view_index.value();
            let view = self.view_bytes(view_index, &format!("accessor {index}"))?;
            let stride = match self.root.buffer_views[view_index].byte_stride {
                Some(s) => s.0 as u64,
                None => elem,
            };
            if stride < elem {
                return Err(self.bad_accessor(
                    index,
                    &format!("byteStride {stride} of buffer view {view_index} is smaller than the element size {elem}"),
                ));
            }
            let offset = a.byte_offset.map_or(0, |o| o.0);
            let needed = if count == 0 {
                Some(offset)
            } else {
                stride
                    .checked_mul(count - 1)
                    .and_then(|x| x.checked_add(offset))
                    .and_then(|x| x.checked_add(elem))
            };
            match needed {
                Some(n) if n <= view.len() as u64 => {}
                _ => {
                    return Err(SceneError::AccessorOutOfRange {
                        path: self.path.to_owned(),
                        accessor: index,
                        view: view_index,
                        needed: needed.unwrap_or(u64::MAX),
                        length: view.len() as u64,
                    });
                }
            }
            // All of these fit in usize: they are bounded by the view length.
            let (offset, stride, elem) = (offset as usize, stride as usize, elem as usize);
            if stride == elem {
                out = view[offset..offset + total as usize].to_vec();
            } else {
                out = Vec::with_capacity(total as usize);
                for i in 0..layout.count {
                    let start = offset + i * stride;
                    out.extend_from_slice(&view[start..start + elem]);
                }
            }
        } else {
            // Zero-filled (typically the base of a sparse accessor); `total` is within budget.
            out = vec![0; total as usize];
        }
        if let Some(sparse) = &a.sparse {
            self.apply_sparse(index, sparse, layout, &mut out)?;
        }
        Ok(out)
    }

    /// Writes the sparse substitutions of accessor `index` into `out`.
    fn apply_sparse(
        &self,
        index: usize,
        sparse: &gltf::json::accessor::sparse::Sparse,
        layout: Layout,
        out: &mut [u8],
    ) -> Result<(), SceneError> {
        let what = format!("accessor {index} (sparse)");
        let n = sparse.count.0;
        if n > layout.count as u64 {
            return Err(self.bad_accessor(index, "sparse count exceeds the accessor count"));
        }
        let n = n as usize;
        let Checked::Valid(ict) = &sparse.indices.component_type else {
            return Err(self.bad_accessor(index, "sparse indices have an invalid component type"));
        };
        let isize_ = ict.0.size();
        let elem = layout.element_size();
        let slice = |view: usize, offset: u64, len: usize| -> Result<&[u8], SceneError> {
            let bytes = self.view_bytes(view, &what)?;
            let end = offset.checked_add(len as u64);
            match end {
                Some(end) if end <= bytes.len() as u64 => Ok(&bytes[offset as usize..end as usize]),
                _ => Err(SceneError::AccessorOutOfRange {
                    path: self.path.to_owned(),
                    accessor: index,
                    view,
                    needed: end.unwrap_or(u64::MAX),
                    length: bytes.len() as u64,
                }),
            }
        };
        let idx = slice(sparse.indices.buffer_view.value(), sparse.indices.byte_offset.0, n * isize_)?;
        let vals = slice(sparse.values.buffer_view.value(), sparse.values.byte_offset.0, n * elem)?;
        for i in 0..n {
            let target = read_uint(ict.0, &idx[i * isize_..]) as usize;
            if target >= layout.count {
                return Err(self.bad_accessor(
                    index,
                    &format!("sparse index {target} is out of range (count {})", layout.count),
                ));
            }
            out[target * elem..(target + 1) * elem].copy_from_slice(&vals[i * elem..(i + 1) * elem]);
        }
        Ok(())
    }

    /// Whether the file uses `KHR_mesh_quantization`, which allows integer vertex attributes.
    fn quantized(&self) -> bool {
        let root = self.root;
        (root.extensions_used.iter().chain(&root.extensions_required)).any(|e| e == QUANTIZATION)
    }

    /// Checks that accessor `index` is a `VEC3` that `usage` (`POSITION` or `NORMAL`) may use:
    /// `FLOAT`, or with `KHR_mesh_quantization` any 8- or 16-bit integer for positions and a
    /// normalized `BYTE` or `SHORT` for normals.
    pub(super) fn vec3_layout(&self, index: usize, what: &str, usage: &str) -> Result<Layout, SceneError> {
        use ComponentType::{F32, I8, I16, U8, U16};
        let normal = usage == "NORMAL";
        let (accept, expected): (&dyn Fn(Type, ComponentType, bool) -> bool, _) = match (
            self.quantized(),
            normal,
        ) {
            (false, _) => (&|t, c, _| t == Type::Vec3 && c == F32, "VEC3 of FLOAT"),
            (true, false) => (
                &|t, c, _| t == Type::Vec3 && matches!(c, F32 | I8 | U8 | I16 | U16),
                "VEC3 of FLOAT, or of (normalized) BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT (KHR_mesh_quantization)",
            ),
            (true, true) => (
                &|t, c, n| t == Type::Vec3 && (c == F32 || (n && matches!(c, I8 | I16))),
                "VEC3 of FLOAT, or of normalized BYTE or SHORT (KHR_mesh_quantization)",
            ),
        };
        self.layout(index, what, usage, accept, expected)
    }

    /// Reads a `VEC3` accessor checked by [`Ctx::vec3_layout`], dequantised to `f32`.
    pub(super) fn read_vec3(&self, index: usize, layout: Layout) -> Result<Vec<glam::Vec3>, SceneError> {
        Ok(self.read_floats::<3>(index, layout)?.into_iter().map(glam::Vec3::from_array).collect())
    }

    /// Checks that accessor `index` is a `TANGENT` accessor: `VEC4` of `FLOAT`, or with
    /// `KHR_mesh_quantization` of normalized `BYTE` or `SHORT`.
    pub(super) fn tangent_layout(&self, index: usize, what: &str) -> Result<Layout, SceneError> {
        use ComponentType::{F32, I8, I16};
        let (accept, expected): (&dyn Fn(Type, ComponentType, bool) -> bool, _) = if self.quantized() {
            (
                &|t, c, n| t == Type::Vec4 && (c == F32 || (n && matches!(c, I8 | I16))),
                "VEC4 of FLOAT, or of normalized BYTE or SHORT (KHR_mesh_quantization)",
            )
        } else {
            (&|t, c, _| t == Type::Vec4 && c == F32, "VEC4 of FLOAT")
        };
        self.layout(index, what, "TANGENT", accept, expected)
    }

    /// Reads a `VEC4` accessor checked by [`Ctx::tangent_layout`], dequantised to `f32`.
    pub(super) fn read_vec4(&self, index: usize, layout: Layout) -> Result<Vec<glam::Vec4>, SceneError> {
        Ok(self.read_floats::<4>(index, layout)?.into_iter().map(glam::Vec4::from_array).collect())
    }

    /// Checks that accessor `index` is a texture-coordinate accessor: `VEC2` of `FLOAT` or
    /// normalized unsigned bytes or shorts, or with `KHR_mesh_quantization` any 8- or 16-bit
    /// integer.
    pub(super) fn uv_layout(&self, index: usize, what: &str, name: &str) -> Result<Layout, SceneError> {
        use ComponentType::{F32, I8, I16, U8, U16};
        let (accept, expected): (&dyn Fn(Type, ComponentType, bool) -> bool, _) = if self.quantized() {
            (
                &|t, c, _| t == Type::Vec2 && matches!(c, F32 | I8 | U8 | I16 | U16),
                "VEC2 of FLOAT, or of (normalized) BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT (KHR_mesh_quantization)",
            )
        } else {
            (
                &|t, c, n| t == Type::Vec2 && (c == F32 || (n && matches!(c, U8 | U16))),
                "VEC2 of FLOAT, normalized UNSIGNED_BYTE or normalized UNSIGNED_SHORT",
            )
        };
        self.layout(index, what, name, accept, expected)
    }

    /// Reads a texture-coordinate accessor checked by [`Ctx::uv_layout`], dequantised to `f32`.
    pub(super) fn read_uv(&self, index: usize, layout: Layout) -> Result<Vec<glam::Vec2>, SceneError> {
        Ok(self.read_floats::<2>(index, layout)?.into_iter().map(glam::Vec2::from_array).collect())
    }

    /// Reads an accessor of `N` components per element as `f32` ([`component_f32`]).
    fn read_floats<const N: usize>(&self, index: usize, layout: Layout) -> Result<Vec<[f32; N]>, SceneError> {
        debug_assert_eq!(layout.components, N);
        let bytes = self.packed(index, layout)?;
        let cs = layout.component.size();
        let element = |e: &[u8]| {
            std::array::from_fn(|i| component_f32(layout.component, layout.normalized, &e[i * cs..]))
        };
        Ok(bytes.chunks_exact(N * cs).map(element).collect())
    }

    /// Checks that accessor `index` is an index accessor (`SCALAR` of unsigned ints).
    pub(super) fn index_layout(&self, index: usize, what: &str) -> Result<Layout, SceneError> {
        self.layout(
            index,
            what,
            "indices",
            &|t, c, _| {
                t == Type::Scalar && matches!(c, ComponentType::U8 | ComponentType::U16 | ComponentType::U32)
            },
            "SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
        )
    }

    /// Reads an index accessor checked by [`Ctx::index_layout`].
    pub(super) fn read_indices(&self, index: usize, layout: Layout) -> Result<Vec<u32>, SceneError> {
        let bytes = self.packed(index, layout)?;
        let cs = layout.component.size();
        Ok(bytes.chunks_exact(cs).map(|c| read_uint(layout.component, c)).collect())
    }
}

/// The extension that allows 8- and 16-bit integer vertex attributes.
const QUANTIZATION: &str = "KHR_mesh_quantization";

/// Component of type `c` at the start of `b` as `f32`. Normalized integers map to `[0, 1]`
/// (unsigned: `c / 255`, `c / 65535`) or `[-1, 1]` (signed: `max(c / 127, -1)`,
/// `max(c / 32767, -1)`), as glTF specifies; other integers keep their value (the
/// dequantisation scale and offset of `KHR_mesh_quantization` are in the node transform).
fn component_f32(c: ComponentType, normalized: bool, b: &[u8]) -> f32 {
    let (value, max) = match c {
        ComponentType::F32 => return f32_at(b, 0),
        ComponentType::I8 => (f32::from(b[0] as i8), 127.0),
        ComponentType::U8 => (f32::from(b[0]), 255.0),
        ComponentType::I16 => (f32::from(i16::from_le_bytes([b[0], b[1]])), 32767.0),
        ComponentType::U16 => (f32::from(u16::from_le_bytes([b[0], b[1]])), 65535.0),
        ComponentType::U32 => (u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32, u32::MAX as f32),
    };
    if normalized { (value / max).max(-1.0) } else { value }
}

/// Little-endian f32 at `at`; callers pass slices of at least `at + 4` bytes.
fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// Little-endian unsigned int of component type `c` at the start of `b`.
fn read_uint(c: ComponentType, b: &[u8]) -> u32 {
    match c {
        ComponentType::U8 | ComponentType::I8 => b[0] as u32,
        ComponentType::U16 | ComponentType::I16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn components_dequantise_as_gltf_specifies() {
        use ComponentType::{F32, I8, I16, U8, U16};
        let cases: &[(ComponentType, bool, &[u8], f32)] = &[
            (F32, false, &1.5f32.to_le_bytes(), 1.5),
            (I8, false, &[0x80], -128.0),
            (I8, true, &[0x80], -1.0), // -128 / 127 clamps to -1
            (I8, true, &[0x81], -1.0),
            (I8, true, &[127], 1.0),
            (U8, false, &[255], 255.0),
            (U8, true, &[255], 1.0),
            (I16, false, &(-300i16).to_le_bytes(), -300.0),
            (I16, true, &i16::MIN.to_le_bytes(), -1.0),
            (I16, true, &16384i16.to_le_bytes(), 16384.0 / 32767.0),
            (U16, false, &65535u16.to_le_bytes(), 65535.0),
            (U16, true, &32768u16.to_le_bytes(), 32768.0 / 65535.0),
        ];
        for &(c, normalized, bytes, expected) in cases {
            assert_eq!(component_f32(c, normalized, bytes), expected, "{c:?} {normalized} {bytes:?}");
        }
    }
}
