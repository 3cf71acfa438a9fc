//! Writing files and encoding PNG.

use std::path::Path;

use crate::PlotError;

/// Writes `bytes` to `path`, mapping failures to [`PlotError::Io`].
pub(crate) fn write(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    std::fs::write(path, bytes).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Averages `factor`×`factor` blocks of an RGB image (anti-aliasing of a
/// supersampled rendering).
pub(crate) fn downsample(rgb: &[u8], (w, h): (u32, u32), factor: u32) -> Vec<u8> {
    let (w, h, f) = (w as usize, h as usize, factor.max(1) as usize);
    let (ow, oh) = (w / f, h / f);
    let mut out = vec![0u8; ow * oh * 3];
    let n = (f * f) as u32;
    for oy in 0..oh {
        for ox in 0..ow {
            let mut acc = [0u32; 3];
            for dy in 0..f {
                let row = (oy * f + dy) * w;
                for dx in 0..f {
                    let i = (row + ox * f + dx) * 3;
                    for c in 0..3 {
                        acc[c] += u32::from(rgb[i + c]);
                    }
                }
            }
            let o = (oy * ow + ox) * 3;
            for c in 0..3 {
                out[o + c] = ((acc[c] + n / 2) / n) as u8;
            }
        }
    }
    out
}

/// Encodes an RGB image as PNG.
pub(crate) fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, PlotError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(PlotError::render)?;
        writer.write_image_data(rgb).map_err(PlotError::render)?;
        writer.finish().map_err(PlotError::render)?;
    }
    Ok(out)
}
