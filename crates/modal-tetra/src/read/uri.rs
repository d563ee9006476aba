//! The two kinds of URI a glTF buffer may have (glTF 2.0 §2.8, "URIs"): a
//! `data:` URI (RFC 2397) that holds the bytes, or a relative reference
//! (RFC 3986 §4.2, a path without scheme or authority) to a file.
//!
//! A path's `%XX` escapes are decoded, and the result read as UTF-8, as the
//! spec asks: `bar%20data.bin` names the file `bar data.bin`. A stray `%`
//! that starts no escape is kept as it is, as browsers do. `..` segments are
//! kept (exporters write them for shared buffers). Refused, because the spec
//! asks clients to read only relative paths and `data:` URIs and a file that
//! relies on more opens nowhere else: any other scheme (`http:`, `file:`, a
//! drive letter `C:`) and absolute paths (`/dev/zero`, `//host/share`).

use std::path::PathBuf;

/// What a buffer's URI holds or names.
#[derive(Debug, PartialEq)]
pub(super) enum BufferUri {
    /// The bytes of a `data:` URI.
    Data(Vec<u8>),
    /// A relative path, decoded, to join to the `.gltf`'s folder.
    Relative(PathBuf),
}

/// Reads `uri`; the error says why it is refused, for the caller to prefix
/// with the buffer.
pub(super) fn parse(uri: &str) -> Result<BufferUri, String> {
    match scheme(uri) {
        Some(scheme) if scheme.eq_ignore_ascii_case("data") => {
            data(&uri[scheme.len() + 1..]).map(BufferUri::Data)
        }
        Some(scheme) => Err(format!(
            "the URI scheme '{scheme}:' is not read (glTF buffers are relative paths or data: URIs)"
        )),
        None => relative(uri).map(BufferUri::Relative),
    }
}

/// The scheme of `uri` (RFC 3986 §3.1: a letter, then letters, digits, `+`,
/// `-` or `.`, before the first `:`), if it has one.
fn scheme(uri: &str) -> Option<&str> {
    let (scheme, _) = uri.split_once(':')?;
    let mut chars = scheme.chars();
    let valid = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
    valid.then_some(scheme)
}

/// The bytes of a data URI after `data:`: `[media type][;base64],payload`.
/// Any media type is taken (glTF names `application/octet-stream` and
/// `application/gltf-buffer`); a payload without `;base64` is percent-encoded.
fn data(rest: &str) -> Result<Vec<u8>, String> {
    let (header, payload) = rest.split_once(',').ok_or("its data: URI has no ',' before the data")?;
    let is_base64 = header.rsplit(';').next().is_some_and(|p| p.eq_ignore_ascii_case("base64"));
    if is_base64 {
        base64(payload)
    } else {
        Ok(percent_decoded(payload))
    }
}

/// The path of a relative reference, percent-decoded.
fn relative(uri: &str) -> Result<PathBuf, String> {
    let path = String::from_utf8(percent_decoded(uri))
        .map_err(|_| format!("'{uri}' is not UTF-8 once its %-escapes are decoded"))?;
    // `has_root` rather than `is_absolute`: on Windows `/x` has a root but no drive.
    if path.starts_with(['/', '\\']) || PathBuf::from(&path).has_root() {
        return Err(format!("'{uri}' is an absolute path (glTF buffers are relative paths or data: URIs)"));
    }
    Ok(PathBuf::from(path))
}

/// `text` with each `%XX` (two hex digits) replaced by the byte it encodes.
fn percent_decoded(text: &str) -> Vec<u8> {
    let bytes = text.as_bytes();
    let hex = |i: usize| bytes.get(i).and_then(|&b| char::from(b).to_digit(16));
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match (bytes[i], hex(i + 1), hex(i + 2)) {
            (b'%', Some(high), Some(low)) => {
                out.push((high * 16 + low) as u8);
                i += 3;
            }
            (byte, _, _) => {
                out.push(byte);
                i += 1;
            }
        }
    }
    out
}

/// Decodes base64 (RFC 4648, standard or URL-safe alphabet, padding optional).
fn base64(text: &str) -> Result<Vec<u8>, String> {
    let digits = text.trim_end_matches('=');
    let mut out = Vec::with_capacity(digits.len() / 4 * 3 + 2);
    let (mut bits, mut held) = (0u32, 0u32);
    for (i, c) in digits.bytes().enumerate() {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return Err(format!("its base64 data has {:?} at character {i}", char::from(c))),
        };
        bits = (bits << 6) | u32::from(value);
        held += 6;
        if held >= 8 {
            held -= 8;
            out.push((bits >> held) as u8);
            bits &= (1 << held) - 1;
        }
    }
    // Four digits make three bytes; a lone digit left over makes none.
    if digits.len() % 4 == 1 {
        return Err("its base64 data is cut short (one digit too many)".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_are_decoded_and_stray_percents_kept() {
        assert_eq!(percent_decoded("bar%20data.bin"), b"bar data.bin");
        assert_eq!(percent_decoded("caf%C3%A9%2fx"), "café/x".as_bytes());
        assert_eq!(percent_decoded("100%.bin%4"), b"100%.bin%4");
        assert_eq!(percent_decoded("%+1%zz"), b"%+1%zz");
    }

    #[test]
    fn base64_decodes_every_tail_length() {
        assert_eq!(base64("").unwrap(), b"");
        assert_eq!(base64("Zg==").unwrap(), b"f");
        assert_eq!(base64("Zm8=").unwrap(), b"fo");
        assert_eq!(base64("Zm9v").unwrap(), b"foo");
        assert_eq!(base64("Zm9vYg").unwrap(), b"foob");
        assert_eq!(base64("AP8A_-8").unwrap(), base64("AP8A/+8=").unwrap());
        assert!(base64("Zm9vY").is_err());
        assert!(base64("Zm 9v").is_err());
    }

    #[test]
    fn uris_are_data_relative_or_refused() {
        let data = |uri: &str| parse(uri).unwrap();
        assert_eq!(data("data:application/octet-stream;base64,Zm9v"), BufferUri::Data(b"foo".to_vec()));
        assert_eq!(data("DATA:application/gltf-buffer;BASE64,Zm9v"), BufferUri::Data(b"foo".to_vec()));
        assert_eq!(data("data:,a%20b"), BufferUri::Data(b"a b".to_vec()));
        assert_eq!(data("../bins/bar%20data.bin"), BufferUri::Relative("../bins/bar data.bin".into()));
        assert_eq!(data("x/dir:a.bin"), BufferUri::Relative("x/dir:a.bin".into()), "':' after a '/'");
        for refused in
            ["/dev/zero", "%2Fdev%2Fzero", "//host/a.bin", "file:///a.bin", "http://x/a.bin", "C:a.bin"]
        {
            assert!(parse(refused).is_err(), "{refused}");
        }
        assert!(parse("data:application/octet-stream;base64").is_err(), "no ','");
        assert!(parse("%FF.bin").is_err(), "not UTF-8");
    }
}
