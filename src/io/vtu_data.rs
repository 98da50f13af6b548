//! The bytes of a binary VTU data array: base64 text (inline `binary` arrays, appended
//! `base64` data) or raw bytes (appended `raw` data), a UInt32 or UInt64 header, and the
//! data either as it is or in zlib- or LZ4-compressed blocks.
//!
//! VTK encodes a compressed array's header and its data as separate base64 runs (each
//! padded), an uncompressed one as one run or two; [`base64_runs`] decodes any such
//! sequence of padded runs into the bytes they hold, so the header need not be guessed.
//! Decompression uses `flate2` (zlib) and `lz4_flex`; a block's declared size is refused
//! when its compressed bytes could not hold it, so no header makes us reserve more memory
//! than the file's size justifies.

use std::io::Read;

use base64::engine::general_purpose::STANDARD;
use base64::Engine;

/// A VTU `compressor` attribute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Compressor {
    None,
    Zlib,
    Lz4,
}

impl Compressor {
    /// The compressor named by the `compressor` attribute (`None` when absent or empty);
    /// `Err` names an unsupported one.
    pub fn parse(name: Option<&[u8]>) -> Result<Compressor, String> {
        match name.map(|n| n.trim_ascii()) {
            None | Some(b"") => Ok(Compressor::None),
            Some(b"vtkZLibDataCompressor") => Ok(Compressor::Zlib),
            Some(b"vtkLZ4DataCompressor") => Ok(Compressor::Lz4),
            Some(other) => Err(format!(
                "compressor '{}' is not supported (zlib and LZ4 are; save the file with one \
                 of them or uncompressed)",
                String::from_utf8_lossy(other)
            )),
        }
    }

    /// Largest size `n` compressed bytes can decompress to (zlib's deflate tops out
    /// near 1032:1, LZ4 near 255:1), with a margin.
    fn max_expansion(self, n: u64) -> u64 {
        match self {
            Compressor::None => n,
            Compressor::Zlib => n.saturating_mul(1032).saturating_add(64),
            Compressor::Lz4 => n.saturating_mul(256).saturating_add(64),
        }
    }
}

/// How a binary array is laid out.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    /// Header integers are UInt64 (else UInt32).
    pub header64: bool,
    pub big_endian: bool,
    pub compressor: Compressor,
}

/// The bytes held by base64 text: whitespace is skipped, and the text may be several
/// padded runs one after another (each `=`-padded run is decoded on its own). Decoding
/// stops at the first byte that is neither base64 nor whitespace (the `</AppendedData>`
/// after appended data). `Err` is a message.
pub(crate) fn base64_runs(text: &[u8]) -> Result<Vec<u8>, String> {
    let is_b64 = |b: u8| b.is_ascii_alphanumeric() || b == b'+' || b == b'/' || b == b'=';
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .take_while(|&b| is_b64(b) || b.is_ascii_whitespace())
        .filter(|&b| is_b64(b))
        .collect();
    let mut out = Vec::with_capacity(clean.len() / 4 * 3);
    let mut s = 0;
    while s < clean.len() {
        // The run ends with the quad holding its first '=' (and that quad's other '=').
        let end = match clean[s..].iter().position(|&b| b == b'=') {
            Some(k) => (s + (k / 4 + 1) * 4).min(clean.len()),
            None => clean.len(),
        };
        STANDARD
            .decode_vec(&clean[s..end], &mut out)
            .map_err(|e| format!("invalid base64 data: {e}"))?;
        s = end;
    }
    Ok(out)
}

/// Reads header integers from a byte slice.
struct Header<'b> {
    bytes: &'b [u8],
    pos: usize,
    layout: Layout,
}

impl Header<'_> {
    fn next(&mut self, what: &str) -> Result<u64, String> {
        let size = if self.layout.header64 { 8 } else { 4 };
        let Some(s) = self.bytes.get(self.pos..self.pos + size) else {
            return Err(format!("binary data array ends inside its header ({what})"));
        };
        self.pos += size;
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(s);
        if self.layout.big_endian {
            b[..size].reverse();
        }
        Ok(u64::from_le_bytes(b))
    }
}

/// The data bytes of an array whose (header + data) bytes start `bytes` (which may run
/// on past the array). `Err` is a message.
pub(crate) fn array_bytes(bytes: &[u8], layout: Layout) -> Result<Vec<u8>, String> {
    let mut h = Header {
        bytes,
        pos: 0,
        layout,
    };
    if layout.compressor == Compressor::None {
        let n = h.next("byte count")?;
        let rest = &bytes[h.pos..];
        if n > rest.len() as u64 {
            return Err(format!(
                "binary data array declares {n} bytes but holds {}",
                rest.len()
            ));
        }
        return Ok(rest[..n as usize].to_vec());
    }
    let nblocks = h.next("block count")?;
    let block = h.next("block size")?;
    let last = h.next("last block size")?;
    let hsize: u64 = if layout.header64 { 8 } else { 4 };
    if nblocks.saturating_mul(hsize) > (bytes.len() - h.pos) as u64 {
        return Err(format!(
            "compressed data array declares {nblocks} blocks, more than its bytes can hold"
        ));
    }
    let mut sizes = Vec::with_capacity(nblocks as usize);
    for _ in 0..nblocks {
        sizes.push(h.next("compressed block size")?);
    }
    let mut at = h.pos;
    let mut out = Vec::new();
    for (i, &csize) in sizes.iter().enumerate() {
        let full = if i + 1 == sizes.len() && last != 0 {
            last
        } else {
            block
        };
        let Some(src) = (at as u64)
            .checked_add(csize)
            .filter(|&e| e <= bytes.len() as u64)
            .map(|e| &bytes[at..e as usize])
        else {
            return Err(format!(
                "compressed block {i} declares {csize} bytes, past the end of the data"
            ));
        };
        at += csize as usize;
        if full > layout.compressor.max_expansion(csize) {
            return Err(format!(
                "compressed block {i} declares {full} bytes from {csize} compressed ones"
            ));
        }
        let start = out.len();
        match layout.compressor {
            Compressor::Zlib => {
                flate2::read::ZlibDecoder::new(src)
                    .take(full)
                    .read_to_end(&mut out)
                    .map_err(|e| format!("compressed block {i}: zlib: {e}"))?;
            }
            Compressor::Lz4 => {
                out.resize(start + full as usize, 0);
                let n = lz4_flex::block::decompress_into(src, &mut out[start..])
                    .map_err(|e| format!("compressed block {i}: lz4: {e}"))?;
                out.truncate(start + n);
            }
            Compressor::None => unreachable!("handled above"),
        }
        if (out.len() - start) as u64 != full {
            return Err(format!(
                "compressed block {i} holds {} bytes, its header says {full}",
                out.len() - start
            ));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn b64(b: &[u8]) -> String {
        STANDARD.encode(b)
    }

    #[test]
    fn padded_runs_decode_as_their_concatenation() {
        let (a, b) = (vec![1u8, 2, 3, 4], vec![5u8, 6, 7, 8, 9]);
        let apart = format!("{}\n  {}", b64(&a), b64(&b));
        let joined = b64(&[a.clone(), b.clone()].concat());
        let want = [a, b].concat();
        assert_eq!(base64_runs(apart.as_bytes()).unwrap(), want);
        assert_eq!(base64_runs(joined.as_bytes()).unwrap(), want);
        // Stops at the end of appended data.
        let tail = format!("{joined}\n</AppendedData>");
        assert_eq!(base64_runs(tail.as_bytes()).unwrap(), want);
        assert!(base64_runs(b"AB=C").is_err());
    }

    #[test]
    fn zlib_and_lz4_blocks_and_both_header_types() {
        let data: Vec<u8> = (0..1000u32).flat_map(|i| (i % 7).to_le_bytes()).collect();
        for header64 in [false, true] {
            for compressor in [Compressor::Zlib, Compressor::Lz4] {
                let block = 1500usize;
                let chunks: Vec<&[u8]> = data.chunks(block).collect();
                let packed: Vec<Vec<u8>> = chunks
                    .iter()
                    .map(|c| match compressor {
                        Compressor::Zlib => {
                            let mut e = flate2::write::ZlibEncoder::new(
                                Vec::new(),
                                flate2::Compression::default(),
                            );
                            e.write_all(c).unwrap();
                            e.finish().unwrap()
                        }
                        _ => lz4_flex::block::compress(c),
                    })
                    .collect();
                let put = |v: &mut Vec<u8>, x: usize| {
                    if header64 {
                        v.extend_from_slice(&(x as u64).to_le_bytes())
                    } else {
                        v.extend_from_slice(&(x as u32).to_le_bytes())
                    }
                };
                let mut bytes = Vec::new();
                put(&mut bytes, chunks.len());
                put(&mut bytes, block);
                put(&mut bytes, data.len() % block);
                for p in &packed {
                    put(&mut bytes, p.len());
                }
                for p in &packed {
                    bytes.extend_from_slice(p);
                }
                let layout = Layout {
                    header64,
                    big_endian: false,
                    compressor,
                };
                assert_eq!(array_bytes(&bytes, layout).unwrap(), data);
                // A block claiming far more than its bytes can hold is refused.
                let mut bad = bytes.clone();
                let size = if header64 { 8 } else { 4 };
                bad[size..2 * size].copy_from_slice(&vec![0xff; size]);
                let e = array_bytes(&bad, layout).unwrap_err();
                assert!(e.contains("declares"), "{e}");
            }
        }
    }
}
