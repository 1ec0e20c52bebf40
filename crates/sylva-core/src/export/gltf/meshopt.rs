//! `EXT_meshopt_compression`: every vertex, index and animation buffer view compressed with
//! meshoptimizer's codecs (the `meshopt` crate; vertex codec version 0, the one the `EXT_`
//! extension allows), images left as they are. The compressed streams and the images fill the
//! file's buffer; a second buffer, `fallback`, stands where the uncompressed views lie and has
//! no data, so the extension is required (a loader without it could not read the file).

use super::*;

/// Strides the vertex codec is run with (bytes; the extension wants a multiple of 4, at most
/// 256). A view with another stride stays uncompressed.
const STRIDES: [usize; 9] = [4, 8, 12, 16, 20, 24, 28, 32, 64];

/// Encodes `bytes` as `bytes.len() / N` elements of `N` bytes.
fn encode_vertices<const N: usize>(bytes: &[u8]) -> Option<Vec<u8>> {
    let elements: Vec<[u8; N]> = bytes.chunks_exact(N).map(|c| c.try_into().expect("chunks of N")).collect();
    ::meshopt::encode_vertex_buffer_level(&elements, 2, Some(0)).ok()
}

fn encode_attributes(bytes: &[u8], stride: usize) -> Option<Vec<u8>> {
    match stride {
        4 => encode_vertices::<4>(bytes),
        8 => encode_vertices::<8>(bytes),
        12 => encode_vertices::<12>(bytes),
        16 => encode_vertices::<16>(bytes),
        20 => encode_vertices::<20>(bytes),
        24 => encode_vertices::<24>(bytes),
        28 => encode_vertices::<28>(bytes),
        32 => encode_vertices::<32>(bytes),
        64 => encode_vertices::<64>(bytes),
        _ => None,
    }
}

/// The element size of the accessors reading a view (they agree: the builder gives every
/// accessor its own view), or its stride.
fn element_size(root: &json::Root, view: usize) -> Option<usize> {
    if let Some(s) = root.buffer_views[view].byte_stride {
        return Some(s.0);
    }
    root.accessors.iter().find(|a| a.buffer_view.is_some_and(|v| v.value() == view)).and_then(|a| {
        let (Valid(c), Valid(t)) = (&a.component_type, &a.type_) else { return None };
        Some(c.0.size() * t.multiplicity())
    })
}

/// Compresses the document's buffer views in place (see the module documentation). Returns
/// the bytes saved.
pub(super) fn compress(root: &mut json::Root, bin: &mut Vec<u8>) -> usize {
    let before = bin.len();
    let mut packed: Vec<u8> = Vec::with_capacity(bin.len() / 2);
    let mut fallback_len = 0usize;
    let images: std::collections::HashSet<usize> =
        root.images.iter().filter_map(|i| i.buffer_view.map(|v| v.value())).collect();
    for v in 0..root.buffer_views.len() {
        let view = &root.buffer_views[v];
        let (offset, len) = (view.byte_offset.map_or(0, |o| o.0 as usize), view.byte_length.0 as usize);
        let data = &bin[offset..offset + len];
        let indices = matches!(view.target, Some(Valid(json::buffer::Target::ElementArrayBuffer)));
        let encoded = if images.contains(&v) {
            None
        } else if indices {
            let size = element_size(root, v).unwrap_or(4);
            let all: Vec<u32> = match size {
                2 => data.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]]) as u32).collect(),
                _ => data.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect(),
            };
            let vertices = all.iter().max().map_or(0, |&m| m as usize + 1);
            (all.len() % 3 == 0)
                .then(|| ::meshopt::encode_index_buffer(&all, vertices).ok())
                .flatten()
                .map(|e| (e, size, all.len(), "TRIANGLES"))
        } else {
            element_size(root, v)
                .filter(|s| STRIDES.contains(s) && len % s == 0)
                .and_then(|s| encode_attributes(data, s).map(|e| (e, s, len / s, "ATTRIBUTES")))
        };
        while packed.len() % 4 != 0 {
            packed.push(0);
        }
        let view = &mut root.buffer_views[v];
        match encoded {
            Some((e, stride, count, mode)) => {
                while fallback_len % 4 != 0 {
                    fallback_len += 1;
                }
                let mut ext = json::extensions::buffer::View::default();
                ext.others.insert(
                    "EXT_meshopt_compression".into(),
                    serde_json::json!({
                        "buffer": 0,
                        "byteOffset": packed.len(),
                        "byteLength": e.len(),
                        "byteStride": stride,
                        "count": count,
                        "mode": mode,
                    }),
                );
                view.extensions = Some(ext);
                view.buffer = json::Index::new(1);
                view.byte_offset = Some(USize64(fallback_len as u64));
                fallback_len += len;
                packed.extend_from_slice(&e);
            }
            None => {
                view.byte_offset = Some(USize64(packed.len() as u64));
                packed.extend_from_slice(data);
            }
        }
    }
    while packed.len() % 4 != 0 {
        packed.push(0);
    }
    let mut ext = json::extensions::buffer::Buffer::default();
    ext.others.insert("EXT_meshopt_compression".into(), serde_json::json!({ "fallback": true }));
    root.buffers.push(json::Buffer {
        byte_length: USize64(fallback_len as u64),
        name: Some("fallback".into()),
        uri: None,
        extensions: Some(ext),
        extras: Default::default(),
    });
    for list in [&mut root.extensions_used, &mut root.extensions_required] {
        list.push("EXT_meshopt_compression".into());
    }
    *bin = packed;
    root.buffers[0].byte_length = USize64(bin.len() as u64);
    before.saturating_sub(bin.len())
}
