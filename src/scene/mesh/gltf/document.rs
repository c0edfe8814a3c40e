//! A glTF file's JSON and its buffers, checked before anything is decoded: every index the
//! reader follows in range, each buffer read like the mesh file itself and its `byteLength`
//! checked, each buffer view inside its buffer; and the images' sources.

use crate::input_file::{format_size, read_regular_file, MESH_FILE_LIMIT};
use crate::scene::mesh::{one_line, read_mesh_bytes, ImageSource};
use base64::Engine as _;
use gltf::json;
use std::path::{Path, PathBuf};

/// The file's JSON, parsed but not checked, and a `.glb`'s binary chunk.
pub(super) fn read_document(path: &Path) -> Result<(json::Root, Option<Vec<u8>>), String> {
    let bytes = read_mesh_bytes(path)?;
    // The gltf crate subtracts the header's 12 bytes from a .glb's declared length unchecked.
    if bytes.starts_with(b"glTF")
        && bytes
            .get(8..12)
            .is_none_or(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]) < 12)
    {
        return Err(
            "malformed glTF: the .glb header is cut short or declares under 12 bytes".into(),
        );
    }
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| format!("malformed glTF: {}", one_line(&e.to_string())))?;
    drop(bytes);
    let gltf::Gltf { document, blob } = gltf;
    Ok((document.into_json(), blob))
}

/// "accessor 99 does not exist (the file has 4)", when `index` is out of range.
pub(super) fn exists(index: usize, len: usize, kind: &str) -> Result<usize, String> {
    if index < len {
        Ok(index)
    } else {
        let plural = match (len, kind) {
            (1, _) => "",
            (_, "mesh") => "es",
            _ => "s",
        };
        Err(format!(
            "{kind} {index} does not exist (the file has {len} {kind}{plural})"
        ))
    }
}

/// The references between buffers, views, accessors and images, checked once so that the
/// rest can index freely.
pub(super) fn check_references(root: &json::Root) -> Result<(), String> {
    let views = root.buffer_views.len();
    for (i, view) in root.buffer_views.iter().enumerate() {
        exists(view.buffer.value(), root.buffers.len(), "buffer")
            .map_err(|e| format!("bufferViews[{i}].buffer: {e}"))?;
    }
    for (i, a) in root.accessors.iter().enumerate() {
        if let Some(v) = a.buffer_view {
            exists(v.value(), views, "buffer view")
                .map_err(|e| format!("accessors[{i}].bufferView: {e}"))?;
        }
        if let Some(s) = &a.sparse {
            exists(s.indices.buffer_view.value(), views, "buffer view")
                .map_err(|e| format!("accessors[{i}].sparse.indices.bufferView: {e}"))?;
            exists(s.values.buffer_view.value(), views, "buffer view")
                .map_err(|e| format!("accessors[{i}].sparse.values.bufferView: {e}"))?;
        }
    }
    for (i, image) in root.images.iter().enumerate() {
        if let Some(v) = image.buffer_view {
            exists(v.value(), views, "buffer view")
                .map_err(|e| format!("images[{i}].bufferView: {e}"))?;
        }
    }
    for (i, texture) in root.textures.iter().enumerate() {
        exists(texture.source.value(), root.images.len(), "image")
            .map_err(|e| format!("textures[{i}].source: {e}"))?;
    }
    Ok(())
}

/// Every buffer's bytes, each read once and cut to its `byteLength` (which must not exceed
/// what was read). External files go through the same checks as the mesh file, and all
/// buffers together stay within the mesh file limit.
pub(super) fn read_buffers(
    root: &json::Root,
    mut blob: Option<Vec<u8>>,
    dir: &Path,
) -> Result<Buffers, String> {
    let declared = root
        .buffers
        .iter()
        .fold(0u64, |sum, b| sum.saturating_add(b.byte_length.0));
    if declared > MESH_FILE_LIMIT {
        return Err(format!(
            "buffers: their byteLengths add up to {declared} bytes, more than glint's limit of {} \
             for a mesh file",
            format_size(MESH_FILE_LIMIT)
        ));
    }
    let mut buffers = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        let mut data = match &buffer.uri {
            Some(uri) => read_uri(uri, dir, "buffer file").map_err(|e| format!("buffers[{i}]: {e}"))?,
            // Only the first buffer may be the .glb's binary chunk.
            None if i == 0 => blob.take().ok_or_else(|| {
                "buffers[0]: no uri, and the file has no binary chunk (a .glb's BIN) to stand for it"
                    .to_string()
            })?,
            None => {
                return Err(format!(
                    "buffers[{i}]: no uri; only buffers[0] may be a .glb's binary chunk"
                ))
            }
        };
        let length = buffer.byte_length.0;
        if (data.len() as u64) < length {
            return Err(format!(
                "buffers[{i}]: byteLength is {length}, but its data holds only {} bytes",
                data.len()
            ));
        }
        data.truncate(length as usize);
        data.shrink_to_fit();
        buffers.push(data);
    }
    Ok(Buffers {
        total: buffers.iter().map(|b| b.len() as u64).sum(),
        data: buffers,
    })
}

/// The file's buffers, each cut to its `byteLength`.
pub(super) struct Buffers {
    pub(super) data: Vec<Vec<u8>>,
    /// Their bytes together, which bound what may be decoded from them.
    pub(super) total: u64,
}

/// The bytes a URI names: a base64 `data:` URI, a `file:` URI, or a path relative to the glTF
/// file's folder (percent-decoded, as URIs are). `what` names the file in messages.
fn read_uri(uri: &str, dir: &Path, what: &str) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, data)) = rest.split_once(";base64,") else {
            return Err("a data: URI that is not base64".to_string());
        };
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("malformed base64 in the data: URI: {e}"));
    }
    let path = resolve_uri(uri, dir)?;
    read_regular_file(&path, MESH_FILE_LIMIT, what).map_err(|e| format!("{}: {e}", path.display()))
}

/// The file a (non-`data:`) URI names.
fn resolve_uri(uri: &str, dir: &Path) -> Result<PathBuf, String> {
    let rest = match uri
        .strip_prefix("file://")
        .or_else(|| uri.strip_prefix("file:"))
    {
        Some(rest) => rest,
        None if uri.contains(':') => {
            return Err(format!(
                "URI {uri:?}: only relative paths, file: and data: URIs are read"
            ))
        }
        None => uri,
    };
    let decoded = urlencoding::decode(rest)
        .map_err(|_| format!("URI {uri:?}: its percent-encoding is not UTF-8"))?;
    Ok(dir.join(&*decoded))
}

pub(super) fn check_buffer_views(root: &json::Root, buffers: &Buffers) -> Result<(), String> {
    for (i, view) in root.buffer_views.iter().enumerate() {
        let b = view.buffer.value();
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let length = view.byte_length.0;
        let available = buffers.data[b].len() as u64;
        if offset.checked_add(length).is_none_or(|end| end > available) {
            return Err(format!(
                "bufferViews[{i}]: byteOffset {offset} + byteLength {length} run past the end of \
                 buffers[{b}] ({available} bytes)"
            ));
        }
        if let Some(stride) = view.byte_stride {
            if !(4..=252).contains(&stride.0) || stride.0 % 4 != 0 {
                return Err(format!(
                    "bufferViews[{i}]: byteStride {} must be a multiple of 4 in [4, 252]",
                    stride.0
                ));
            }
        }
    }
    Ok(())
}

/// Where image `i` comes from: a file its URI names, or bytes in the glTF file (a buffer view
/// or a base64 `data:` URI), which must be a PNG or JPEG image as glTF requires.
pub(super) fn image_source(
    root: &json::Root,
    buffers: &Buffers,
    i: usize,
    dir: &Path,
) -> Result<ImageSource, String> {
    let element = format!("images[{i}]");
    let image = &root.images[i];
    let bytes: Vec<u8> = match (&image.uri, image.buffer_view) {
        (Some(uri), _) if !uri.starts_with("data:") => {
            return Ok(ImageSource::File(
                resolve_uri(uri, dir).map_err(|e| format!("{element}: {e}"))?,
            ))
        }
        (Some(uri), _) => read_uri(uri, dir, "image").map_err(|e| format!("{element}: {e}"))?,
        (None, Some(v)) => {
            // Inside its buffer: check_buffer_views saw it fit.
            let view = &root.buffer_views[v.value()];
            let start = view.byte_offset.map_or(0, |o| o.0) as usize;
            buffers.data[view.buffer.value()][start..start + view.byte_length.0 as usize].to_vec()
        }
        (None, None) => return Err(format!("{element}: neither a uri nor a bufferView")),
    };
    match image::guess_format(&bytes) {
        Ok(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        Ok(other) => {
            return Err(format!(
                "{element}: a {other:?} image; glTF images glint reads are PNG and JPEG"
            ))
        }
        Err(_) => return Err(format!("{element}: not a PNG or JPEG image")),
    }
    Ok(ImageSource::Embedded {
        element,
        bytes: bytes.into(),
    })
}
