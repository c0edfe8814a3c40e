//! Accessors: where their elements lie in the buffer views (offset, stride, count, sparse
//! entries, all checked), and their decoding to indices and floats within a budget that the
//! size of the file's buffers sets.

use super::document::Buffers;
use gltf::json;
use json::accessor::{ComponentType, Type};
use json::validation::Checked;

/// Decoded vertex data may reach this many bytes per byte of the file's buffers (plus
/// [`DECODE_SLACK`]): a byte index becomes a u32, a byte normal component an f32. It bounds
/// memory when accessors overlap or a sparse accessor has no buffer view.
const DECODE_RATIO: u64 = 4;

const DECODE_SLACK: u64 = 1 << 20;

/// Where an accessor's elements lie, checked against its buffer views.
pub(super) struct Layout<'a> {
    index: usize,
    pub(super) count: usize,
    component: ComponentType,
    components: usize,
    normalized: bool,
    /// The bytes from the first element on, and the distance between elements; `None`: zeros.
    data: Option<(&'a [u8], usize)>,
    sparse: Option<Sparse<'a>>,
}

struct Sparse<'a> {
    count: usize,
    index_type: ComponentType,
    indices: &'a [u8],
    values: &'a [u8],
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

pub(super) fn component_name(c: ComponentType) -> &'static str {
    match c {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

pub(super) fn type_name(t: Type) -> &'static str {
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

/// The bytes of buffer view `v` from `offset`, which must hold `needed` bytes.
fn view_bytes<'a>(
    root: &json::Root,
    buffers: &'a Buffers,
    v: usize,
    offset: u64,
    needed: u64,
    what: &dyn Fn() -> String,
) -> Result<&'a [u8], String> {
    let view = &root.buffer_views[v];
    let length = view.byte_length.0;
    if offset.checked_add(needed).is_none_or(|end| end > length) {
        return Err(format!(
            "{}: needs {needed} bytes from byteOffset {offset}, but bufferViews[{v}] holds {length}",
            what()
        ));
    }
    // Inside the buffer: check_buffer_views saw the view fit.
    let start = view.byte_offset.map_or(0, |o| o.0) + offset;
    Ok(&buffers.data[view.buffer.value()][start as usize..(start + needed) as usize])
}

/// The component type of `accessor`, checked against the type `kind` its use needs and
/// against the component types that use allows.
fn checked_component(
    accessor: &json::Accessor,
    field: &str,
    kind: Type,
    is_index: bool,
) -> Result<ComponentType, String> {
    let Checked::Valid(t) = accessor.type_ else {
        return Err(format!("{field}.type: not a glTF accessor type"));
    };
    let Checked::Valid(json::accessor::GenericComponentType(component)) = accessor.component_type
    else {
        return Err(format!("{field}.componentType: not a glTF component type"));
    };
    if t != kind {
        return Err(format!(
            "{field}: type {}, but this use needs {}",
            type_name(t),
            type_name(kind)
        ));
    }
    let allowed = if is_index {
        matches!(
            component,
            ComponentType::U8 | ComponentType::U16 | ComponentType::U32
        )
    } else {
        component != ComponentType::U32
    };
    if !allowed {
        return Err(format!(
            "{field}: componentType {} is not allowed for {}",
            component_name(component),
            if is_index {
                "indices"
            } else {
                "this attribute"
            }
        ));
    }
    Ok(component)
}

/// The dense elements' bytes and stride, inside their buffer view; `None` (zeros) without one.
fn dense_data<'a>(
    root: &json::Root,
    buffers: &'a Buffers,
    accessor: &json::Accessor,
    field: &str,
    kind: Type,
    component: ComponentType,
    element: u64,
) -> Result<Option<(&'a [u8], usize)>, String> {
    let count = accessor.count.0;
    Ok(match accessor.buffer_view {
        Some(v) => {
            let v = v.value();
            let stride = root.buffer_views[v]
                .byte_stride
                .map_or(element, |s| s.0 as u64);
            if stride < element {
                return Err(format!(
                    "{field}: bufferViews[{v}]'s byteStride {stride} is less than one element \
                     ({} of {}, {element} bytes)",
                    type_name(kind),
                    component_name(component)
                ));
            }
            let offset = accessor.byte_offset.map_or(0, |o| o.0);
            // The last element ends `element` bytes after its start.
            let needed = match count {
                0 => 0,
                c => (c - 1)
                    .checked_mul(stride)
                    .and_then(|n| n.checked_add(element))
                    .unwrap_or(u64::MAX),
            };
            let what = || format!("{field}: {count} elements with stride {stride}");
            Some((
                view_bytes(root, buffers, v, offset, needed, &what)?,
                stride as usize,
            ))
        }
        None => {
            // Zeros, but for the sparse values: nothing bounds the count but the file's
            // size, so the elements must not outnumber what its buffers could hold.
            if count.saturating_mul(element) > buffers.total {
                return Err(format!(
                    "{field}: {count} elements of {element} bytes without a bufferView, more \
                     than the file's {} bytes of buffers could hold",
                    buffers.total
                ));
            }
            None
        }
    })
}

/// The sparse entries' indices and values, inside their buffer views.
fn sparse_data<'a>(
    root: &json::Root,
    buffers: &'a Buffers,
    accessor: &json::Accessor,
    field: &str,
    element: u64,
) -> Result<Option<Sparse<'a>>, String> {
    let count = accessor.count.0;
    Ok(match &accessor.sparse {
        None => None,
        Some(s) => {
            let sparse_count = s.count.0;
            if sparse_count > count {
                return Err(format!(
                    "{field}.sparse.count: {sparse_count}, more than the accessor's {count} \
                     elements"
                ));
            }
            let Checked::Valid(json::accessor::IndexComponentType(index_type)) =
                s.indices.component_type
            else {
                return Err(format!(
                    "{field}.sparse.indices.componentType: not a glTF component type"
                ));
            };
            if !matches!(
                index_type,
                ComponentType::U8 | ComponentType::U16 | ComponentType::U32
            ) {
                return Err(format!(
                    "{field}.sparse.indices.componentType: {} is not an index type",
                    component_name(index_type)
                ));
            }
            let index_bytes = sparse_count.saturating_mul(component_size(index_type) as u64);
            let what = || format!("{field}.sparse.indices: {sparse_count} indices");
            let indices = view_bytes(
                root,
                buffers,
                s.indices.buffer_view.value(),
                s.indices.byte_offset.0,
                index_bytes,
                &what,
            )?;
            let what = || format!("{field}.sparse.values: {sparse_count} values");
            let values = view_bytes(
                root,
                buffers,
                s.values.buffer_view.value(),
                s.values.byte_offset.0,
                sparse_count.saturating_mul(element),
                &what,
            )?;
            Some(Sparse {
                count: sparse_count as usize,
                index_type,
                indices,
                values,
            })
        }
    })
}

impl<'a> Layout<'a> {
    /// Accessor `a`, of type `kind`: indices (`is_index`: unsigned integers) or a vertex
    /// attribute (any component type but UNSIGNED_INT; integers are KHR_mesh_quantization's).
    pub(super) fn of(
        root: &json::Root,
        buffers: &'a Buffers,
        a: usize,
        kind: Type,
        is_index: bool,
    ) -> Result<Layout<'a>, String> {
        let accessor = &root.accessors[a];
        let field = format!("accessors[{a}]");
        let component = checked_component(accessor, &field, kind, is_index)?;
        let components = match kind {
            Type::Scalar => 1,
            Type::Vec2 => 2,
            Type::Vec3 => 3,
            _ => 4,
        };
        let element = (components * component_size(component)) as u64;
        let count = accessor.count.0;
        let data = dense_data(root, buffers, accessor, &field, kind, component, element)?;
        let sparse = sparse_data(root, buffers, accessor, &field, element)?;
        Ok(Layout {
            index: a,
            count: count as usize,
            component,
            components,
            normalized: accessor.normalized,
            data,
            sparse,
        })
    }

    fn element_size(&self) -> usize {
        self.components * component_size(self.component)
    }

    /// Element `i`'s bytes in the dense data (`None`: zeros).
    fn element(&self, i: usize) -> Option<&'a [u8]> {
        self.data.map(|(bytes, stride)| &bytes[i * stride..])
    }

    /// Each sparse entry: the element it replaces and the new value's bytes.
    fn sparse_entries(&self) -> Result<Vec<(usize, &'a [u8])>, String> {
        let Some(s) = &self.sparse else {
            return Ok(Vec::new());
        };
        let size = component_size(s.index_type);
        (0..s.count)
            .map(|k| {
                let target = unsigned(&s.indices[k * size..], s.index_type) as usize;
                if target >= self.count {
                    return Err(format!(
                        "accessors[{}].sparse.indices[{k}]: {target}, but the accessor has only {} \
                         elements",
                        self.index, self.count
                    ));
                }
                Ok((target, &s.values[k * self.element_size()..]))
            })
            .collect()
    }

    /// Every element's components as f32, normalized integers mapped to [0, 1] or [-1, 1].
    pub(super) fn floats<const N: usize>(&self) -> Result<Vec<[f32; N]>, String> {
        debug_assert_eq!(N, self.components);
        let component = |bytes: &[u8], c: usize| -> f32 {
            let size = component_size(self.component);
            float(&bytes[c * size..], self.component, self.normalized)
        };
        let mut out: Vec<[f32; N]> = (0..self.count)
            .map(|i| match self.element(i) {
                Some(e) => std::array::from_fn(|c| component(e, c)),
                None => [0.0; N],
            })
            .collect();
        for (target, bytes) in self.sparse_entries()? {
            out[target] = std::array::from_fn(|c| component(bytes, c));
        }
        Ok(out)
    }

    pub(super) fn indices(&self) -> Result<Vec<u32>, String> {
        let mut out: Vec<u32> = (0..self.count)
            .map(|i| self.element(i).map_or(0, |e| unsigned(e, self.component)))
            .collect();
        for (target, bytes) in self.sparse_entries()? {
            out[target] = unsigned(bytes, self.component);
        }
        Ok(out)
    }
}

fn unsigned(bytes: &[u8], c: ComponentType) -> u32 {
    match c {
        ComponentType::U8 | ComponentType::I8 => bytes[0] as u32,
        ComponentType::U16 | ComponentType::I16 => u16::from_le_bytes([bytes[0], bytes[1]]) as u32,
        ComponentType::U32 | ComponentType::F32 => {
            u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
        }
    }
}

/// One component as glTF defines it: floats as they are, normalized integers mapped to
/// [0, 1] (unsigned) or [-1, 1] (signed), other integers as their value.
fn float(bytes: &[u8], c: ComponentType, normalized: bool) -> f32 {
    let (value, max) = match c {
        ComponentType::F32 => {
            return f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        }
        ComponentType::I8 => (bytes[0] as i8 as f32, 127.0),
        ComponentType::U8 => (bytes[0] as f32, 255.0),
        ComponentType::I16 => (i16::from_le_bytes([bytes[0], bytes[1]]) as f32, 32767.0),
        ComponentType::U16 => (u16::from_le_bytes([bytes[0], bytes[1]]) as f32, 65535.0),
        ComponentType::U32 => (unsigned(bytes, c) as f32, u32::MAX as f32),
    };
    if normalized {
        (value / max).max(-1.0)
    } else {
        value
    }
}

/// Reads primitives' accessors, keeping the decoded bytes within a budget set by the size of
/// the file's buffers.
pub(super) struct Decoder<'a> {
    root: &'a json::Root,
    buffers: &'a Buffers,
    budget: u64,
}

impl<'a> Decoder<'a> {
    pub(super) fn new(root: &'a json::Root, buffers: &'a Buffers) -> Decoder<'a> {
        Decoder {
            root,
            buffers,
            budget: DECODE_RATIO * buffers.total + DECODE_SLACK,
        }
    }

    pub(super) fn layout(
        &mut self,
        a: usize,
        kind: Type,
        is_index: bool,
    ) -> Result<Layout<'_>, String> {
        let layout = Layout::of(self.root, self.buffers, a, kind, is_index)?;
        let bytes = layout.count as u64 * layout.components as u64 * 4;
        if bytes > self.budget {
            return Err(format!(
                "accessors[{a}]: decoding it would bring the file's vertex data to more than \
                 {DECODE_RATIO} bytes per byte of its {} bytes of buffers (do its accessors \
                 overlap?)",
                self.buffers.total
            ));
        }
        self.budget -= bytes;
        Ok(layout)
    }
}
