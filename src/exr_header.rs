//! An OpenEXR file's header attributes, read straight from its bytes, for two things the `exr`
//! crate does not do: writing them in a fixed order (it writes them from a hash map, in an
//! order that changes from run to run), and naming a compression it cannot read (its error
//! then says only "unknown compression method").
//!
//! The header follows the 4-byte magic number and 4-byte version field. Each attribute is its
//! name, a NUL, its type name, a NUL, its size (i32, little-endian) and its value; an empty
//! name (a lone NUL) ends the header.

use std::ops::Range;

const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
const MULTI_PART: u32 = 0x1000;

/// The compressions by their header value, as OpenEXR names them.
const COMPRESSIONS: [&str; 14] = [
    "none", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB", "HTJ2K256",
    "HTJ2K32", "LJ2K", "ZSTD",
];

/// The compressions the `exr` crate reads (values 0 to 9).
pub const READABLE_COMPRESSIONS: &[&str] = &[
    "none", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB",
];

/// One attribute, as ranges of the file's bytes.
struct Attribute {
    name: Range<usize>,
    value: Range<usize>,
    /// Name to value, inclusive.
    whole: Range<usize>,
}

/// The first header's attributes, and where they end (at the NUL that closes the header).
fn attributes(file: &[u8]) -> Result<(Vec<Attribute>, usize), String> {
    if file.len() < 8 || file[..4] != MAGIC {
        return Err("not an EXR file".into());
    }
    let truncated = || "the EXR header is truncated".to_string();
    let nul_from = |from: usize| {
        file.get(from..)
            .and_then(|rest| rest.iter().position(|&b| b == 0))
            .map(|p| from + p)
    };
    let mut at = 8;
    let mut attributes = Vec::new();
    loop {
        let name_end = nul_from(at).ok_or_else(truncated)?;
        if name_end == at {
            return Ok((attributes, at));
        }
        let type_end = nul_from(name_end + 1).ok_or_else(truncated)?;
        let size = file.get(type_end + 1..type_end + 5).ok_or_else(truncated)?;
        let size = i32::from_le_bytes([size[0], size[1], size[2], size[3]]);
        let end = usize::try_from(size)
            .ok()
            .and_then(|s| (type_end + 5).checked_add(s))
            .filter(|&end| end <= file.len())
            .ok_or_else(truncated)?;
        attributes.push(Attribute {
            name: at..name_end,
            value: type_end + 5..end,
            whole: at..end,
        });
        at = end;
    }
}

/// Sorts the header attributes of a single-part EXR file by name, in place, so the same image
/// gives the same bytes. The header keeps its length, so the chunk offsets after it stay
/// valid.
pub fn sort_attributes(file: &mut [u8]) -> Result<(), String> {
    if file.len() >= 8 && u32::from_le_bytes([file[4], file[5], file[6], file[7]]) & MULTI_PART != 0
    {
        return Err("a multi-part EXR file".into());
    }
    let (mut attributes, end) = attributes(file)?;
    attributes.sort_by(|a, b| file[a.name.clone()].cmp(&file[b.name.clone()]));
    let sorted: Vec<u8> = attributes
        .iter()
        .flat_map(|a| file[a.whole.clone()].iter().copied())
        .collect();
    file[8..end].copy_from_slice(&sorted);
    Ok(())
}

/// The compression the (first) header names, as OpenEXR calls it ("ZSTD"), if there is one.
pub fn compression(file: &[u8]) -> Option<String> {
    let (attributes, _) = attributes(file).ok()?;
    let value = attributes
        .iter()
        .find(|a| &file[a.name.clone()] == b"compression")
        .and_then(|a| file.get(a.value.clone()))?;
    let code = *value.first()? as usize;
    Some(
        COMPRESSIONS
            .get(code)
            .map_or_else(|| format!("number {code}"), |name| name.to_string()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attribute(name: &str, type_name: &str, value: &[u8]) -> Vec<u8> {
        let mut a = format!("{name}\0{type_name}\0").into_bytes();
        a.extend_from_slice(&(value.len() as i32).to_le_bytes());
        a.extend_from_slice(value);
        a
    }

    /// The magic number, a version, `attributes`, the header's end and a byte of "pixels".
    fn file(attributes: &[Vec<u8>]) -> Vec<u8> {
        let mut f = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        for a in attributes {
            f.extend_from_slice(a);
        }
        f.extend_from_slice(&[0, 42]);
        f
    }

    #[test]
    fn attributes_are_sorted_by_name_in_place() {
        let b = attribute("glint.b", "string", b"xy");
        let a = attribute("glint.a", "string", b"");
        let mut unsorted = file(&[b.clone(), a.clone()]);
        sort_attributes(&mut unsorted).unwrap();
        assert_eq!(unsorted, file(&[a, b]));
        let mut truncated = file(&[attribute("glint.a", "string", b"xyz")]);
        truncated.truncate(20);
        assert!(sort_attributes(&mut truncated).is_err());
    }

    #[test]
    fn the_compression_is_named() {
        let with = |code: u8| file(&[attribute("compression", "compression", &[code])]);
        assert_eq!(compression(&with(9)).as_deref(), Some("DWAB"));
        assert_eq!(compression(&with(13)).as_deref(), Some("ZSTD"));
        assert_eq!(compression(&with(200)).as_deref(), Some("number 200"));
        assert_eq!(compression(&file(&[])), None);
    }
}
