//! Spherical video metadata in MP4 (issue 18, `render --video`): Google's Spherical Video V2
//! boxes, which YouTube and 360° players read, added to the video track's sample entry (e.g.
//! `avc1`) of a file an encoder wrote:
//!
//! - `st3d` (full box): stereo mode, 0 mono, 1 top-bottom (left eye on top), 2 left-right;
//! - `sv3d` (container): `svhd` (full box: the metadata source, a NUL-terminated string) and
//!   `proj` (container): `prhd` (full box: pose yaw, pitch, roll as 16.16 fixed point, all 0)
//!   and `equi` (full box: the projection bounds top, bottom, left, right as 0.32 fixed-point
//!   fractions cropped off each side: all 0 for the whole sphere, left = right = ¼ for VR180's
//!   front half).
//!
//! and, for players that read only the first version, Spherical Video V1's `uuid` box (UUID
//! ffcc8263-f855-4a93-8814-587a02521fdd) at the end of the video track, holding the
//! GSpherical XML ([`spherical_v1_xml`]): projection, stereo mode, and the crop in pixels.
//!
//! Every box around what is added (`stsd`, `stbl`, `minf`, `mdia`, `trak`, `moov`) grows by the
//! bytes added inside it; where `moov` comes before the media data (`faststart`), every chunk
//! offset (`stco`, `co64`) moves by the bytes added in all.

use crate::core::panoramas::panorama::{ImageMap, PanoramaKind};
use crate::error::{Error, Result};

/// Spherical Video V1's box type: `uuid` with this UUID.
pub const SPHERICAL_V1_UUID: [u8; 16] =
    [0xff, 0xcc, 0x82, 0x63, 0xf8, 0x55, 0x4a, 0x93, 0x88, 0x14, 0x58, 0x7a, 0x02, 0x52, 0x1f, 0xdd];

/// How the two eyes share a frame (`st3d`'s stereo mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StereoMode {
    Mono = 0,
    TopBottom = 1,
    LeftRight = 2,
}

/// A box: where it starts, its header length, its end, its type.
#[derive(Clone, Copy, Debug)]
struct BoxAt {
    start: usize,
    header: usize,
    end: usize,
    kind: [u8; 4],
}

/// The boxes in `data[from..to]`, or None where a size does not fit.
fn boxes(data: &[u8], from: usize, to: usize) -> Option<Vec<BoxAt>> {
    let mut out = Vec::new();
    let mut at = from;
    while at + 8 <= to {
        let size32 = u32::from_be_bytes(data[at..at + 4].try_into().ok()?) as usize;
        let kind: [u8; 4] = data[at + 4..at + 8].try_into().ok()?;
        let (size, header) = match size32 {
            0 => (to - at, 8),
            1 => (u64::from_be_bytes(data.get(at + 8..at + 16)?.try_into().ok()?) as usize, 16),
            s => (s, 8),
        };
        if size < header || at.checked_add(size)? > to {
            return None;
        }
        out.push(BoxAt { start: at, header, end: at + size, kind });
        at += size;
    }
    Some(out)
}

fn child(data: &[u8], parent: &BoxAt, kind: &[u8; 4]) -> Option<BoxAt> {
    boxes(data, parent.start + parent.header, parent.end)?.into_iter().find(|b| &b.kind == kind)
}

fn full_box(kind: &[u8; 4], body: &[u8]) -> Vec<u8> {
    let mut out = ((12 + body.len()) as u32).to_be_bytes().to_vec();
    out.extend(kind);
    out.extend([0, 0, 0, 0]); // version 0, flags 0
    out.extend(body);
    out
}

fn container(kind: &[u8; 4], children: &[Vec<u8>]) -> Vec<u8> {
    let body: Vec<u8> = children.concat();
    let mut out = ((8 + body.len()) as u32).to_be_bytes().to_vec();
    out.extend(kind);
    out.extend(body);
    out
}

/// `equi`'s bounds for a panorama (top, bottom, left, right: the share of the full sphere's
/// width or height cropped off that side, 0.32 fixed point).
pub fn equi_bounds(panorama: PanoramaKind) -> [u32; 4] {
    let side = (1.0 - panorama.turn_share() as f64) / 2.0;
    let side = (side * 4294967296.0).round() as u32;
    [0, 0, side, side]
}

/// The `st3d` and, for an equirectangular panorama (the sphere, VR180) or the cubemap, `sv3d`
/// boxes: `equi` with its bounds, or `cbmp` layout 0 (the 3×2 grid, no padding). The fisheye's
/// projection has no `sv3d` type: `st3d` alone.
pub fn spherical_boxes(stereo: StereoMode, panorama: PanoramaKind) -> Vec<u8> {
    let mut out = full_box(b"st3d", &[stereo as u8]);
    let projection = if panorama.is_equirectangular() {
        let bounds: Vec<u8> = equi_bounds(panorama).iter().flat_map(|b| b.to_be_bytes()).collect();
        full_box(b"equi", &bounds)
    } else if panorama.model().image_map() == ImageMap::Cubemap {
        full_box(b"cbmp", &[0; 8])
    } else {
        return out;
    };
    let svhd = full_box(b"svhd", b"twister\0");
    let prhd = full_box(b"prhd", &[0; 12]);
    out.extend(container(b"sv3d", &[svhd, container(b"proj", &[prhd, projection])]));
    out
}

/// Spherical Video V1's XML for an equirectangular panorama of `eye` pixels per eye.
pub fn spherical_v1_xml(stereo: StereoMode, panorama: PanoramaKind, eye: [u32; 2]) -> String {
    let full_width = (eye[0] as f64 / panorama.turn_share() as f64).round() as u32;
    let mode = match stereo {
        StereoMode::Mono => "mono",
        StereoMode::TopBottom => "top-bottom",
        StereoMode::LeftRight => "left-right",
    };
    let tags = [
        ("Spherical", "true".to_string()),
        ("Stitched", "true".to_string()),
        ("StitchingSoftware", "twister".to_string()),
        ("ProjectionType", "equirectangular".to_string()),
        ("StereoMode", mode.to_string()),
        ("CroppedAreaImageWidthPixels", eye[0].to_string()),
        ("CroppedAreaImageHeightPixels", eye[1].to_string()),
        ("FullPanoWidthPixels", full_width.to_string()),
        ("FullPanoHeightPixels", eye[1].to_string()),
        ("CroppedAreaLeftPixels", ((full_width - eye[0]) / 2).to_string()),
        ("CroppedAreaTopPixels", "0".to_string()),
    ];
    let body: String = tags.iter().map(|(k, v)| format!("<GSpherical:{k}>{v}</GSpherical:{k}>")).collect();
    format!(
        "<?xml version=\"1.0\"?><rdf:SphericalVideo xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\" \
         xmlns:GSpherical=\"http://ns.google.com/videos/1.0/spherical/\">{body}</rdf:SphericalVideo>"
    )
}

/// The V1 `uuid` box holding `xml`.
fn spherical_v1_box(xml: &str) -> Vec<u8> {
    let mut body = SPHERICAL_V1_UUID.to_vec();
    body.extend(xml.as_bytes());
    container(b"uuid", &[body])
}

/// The XML of every Spherical Video V1 box in the file's tracks (tests, checks).
pub fn find_spherical_v1(data: &[u8]) -> Vec<String> {
    find_boxes(data, &["moov", "trak", "uuid"])
        .into_iter()
        .filter(|b| b.starts_with(&SPHERICAL_V1_UUID))
        .map(|b| String::from_utf8_lossy(&b[16..]).into_owned())
        .collect()
}

/// `mp4` (named `name` in errors) with the spherical boxes added to its video track's first
/// sample entry, and for an equirectangular panorama of `eye` pixels per eye the V1 box at the
/// end of that track.
pub fn with_spherical_metadata(
    mp4: &[u8],
    name: &str,
    stereo: StereoMode,
    panorama: PanoramaKind,
    eye: [u32; 2],
) -> Result<Vec<u8>> {
    let bad = |what: &str| Error::output(name, format!("cannot add the spherical metadata: {what}"));
    let top = boxes(mp4, 0, mp4.len()).ok_or_else(|| bad("not an MP4 file"))?;
    let moov = *top.iter().find(|b| &b.kind == b"moov").ok_or_else(|| bad("no moov box"))?;
    let mdat_after = top.iter().any(|b| &b.kind == b"mdat" && b.start > moov.start);
    // The video track: the trak whose handler is 'vide'.
    let traks = boxes(mp4, moov.start + moov.header, moov.end).ok_or_else(|| bad("a broken moov box"))?;
    let (trak, mdia, minf, stbl, stsd) = traks
        .iter()
        .filter(|b| &b.kind == b"trak")
        .find_map(|trak| {
            let mdia = child(mp4, trak, b"mdia")?;
            let hdlr = child(mp4, &mdia, b"hdlr")?;
            (mp4.get(hdlr.start + hdlr.header + 8..hdlr.start + hdlr.header + 12)? == b"vide").then_some(())?;
            let minf = child(mp4, &mdia, b"minf")?;
            let stbl = child(mp4, &minf, b"stbl")?;
            let stsd = child(mp4, &stbl, b"stsd")?;
            Some((*trak, mdia, minf, stbl, stsd))
        })
        .ok_or_else(|| bad("no video track"))?;
    // stsd: full box header, entry count, then sample entries; the first is the video's.
    let entries = boxes(mp4, stsd.start + stsd.header + 8, stsd.end).ok_or_else(|| bad("a broken stsd box"))?;
    let entry = *entries.first().ok_or_else(|| bad("no sample entry"))?;
    let added = spherical_boxes(stereo, panorama);
    let v1 =
        if panorama.is_equirectangular() { spherical_v1_box(&spherical_v1_xml(stereo, panorama, eye)) } else { vec![] };
    let grow = added.len() + v1.len();
    let mut out = Vec::with_capacity(mp4.len() + grow);
    out.extend_from_slice(&mp4[..entry.end]);
    out.extend_from_slice(&added);
    out.extend_from_slice(&mp4[entry.end..trak.end]);
    out.extend_from_slice(&v1);
    out.extend_from_slice(&mp4[trak.end..]);
    // Every box holding what was added grows (32-bit sizes; a 64-bit one keeps its place; every
    // size field lies before the first insertion, so none has moved).
    for b in [moov, trak, mdia, minf, stbl, stsd, entry] {
        let grow = if b.start <= trak.start { grow } else { added.len() };
        let field = if b.header == 16 { b.start + 8 } else { b.start };
        if b.header == 16 {
            let size = u64::from_be_bytes(out[field..field + 8].try_into().expect("8 bytes")) + grow as u64;
            out[field..field + 8].copy_from_slice(&size.to_be_bytes());
        } else {
            let size = u32::from_be_bytes(out[field..field + 4].try_into().expect("4 bytes")) as usize + grow;
            let size = u32::try_from(size).map_err(|_| bad("a box grows beyond 4 GiB"))?;
            out[field..field + 4].copy_from_slice(&size.to_be_bytes());
        }
    }
    if mdat_after {
        // The media data moved: every chunk offset of every track follows it.
        shift_chunk_offsets(&mut out, moov.start + moov.header, moov.end + grow, grow, &bad)?;
    }
    Ok(out)
}

/// Adds `grow` to every chunk offset (stco, co64) of every track in the moov box's body
/// `[body, end)` of `out`.
fn shift_chunk_offsets(
    out: &mut [u8],
    body: usize,
    end: usize,
    grow: usize,
    bad: &dyn Fn(&str) -> Error,
) -> Result<()> {
    let traks = boxes(out, body, end).ok_or_else(|| bad("a broken moov box"))?;
    for trak in traks.iter().filter(|b| &b.kind == b"trak") {
        let stbl = child(out, trak, b"mdia")
            .and_then(|m| child(out, &m, b"minf"))
            .and_then(|m| child(out, &m, b"stbl"))
            .ok_or_else(|| bad("a track without a sample table"))?;
        for table in boxes(out, stbl.start + stbl.header, stbl.end).ok_or_else(|| bad("a broken stbl box"))? {
            let wide = match &table.kind {
                b"stco" => false,
                b"co64" => true,
                _ => continue,
            };
            let body = table.start + table.header + 4;
            let count = u32::from_be_bytes(out[body..body + 4].try_into().expect("4 bytes")) as usize;
            let step = if wide { 8 } else { 4 };
            if body + 4 + count * step > table.end {
                return Err(bad("a chunk offset table longer than its box"));
            }
            for k in 0..count {
                let at = body + 4 + k * step;
                if wide {
                    let v = u64::from_be_bytes(out[at..at + 8].try_into().expect("8 bytes")) + grow as u64;
                    out[at..at + 8].copy_from_slice(&v.to_be_bytes());
                } else {
                    let v = u32::from_be_bytes(out[at..at + 4].try_into().expect("4 bytes")) as u64 + grow as u64;
                    let v = u32::try_from(v).map_err(|_| bad("a chunk offset beyond 4 GiB"))?;
                    out[at..at + 4].copy_from_slice(&v.to_be_bytes());
                }
            }
        }
    }
    Ok(())
}

/// The boxes named by a path from the top (e.g. `["moov", "trak"]`), for tests and checks: each
/// match's body.
pub fn find_boxes<'a>(data: &'a [u8], path: &[&str]) -> Vec<&'a [u8]> {
    let mut level: Vec<(usize, usize)> = vec![(0, data.len())];
    for (depth, name) in path.iter().enumerate() {
        let mut next = Vec::new();
        for &(from, to) in &level {
            for b in boxes(data, from, to).unwrap_or_default() {
                if b.kind == name.as_bytes() {
                    // Sample entries and `stsd` have fields before their children.
                    let skip = match (*name, depth) {
                        ("stsd", _) => 8,
                        ("avc1" | "hev1" | "hvc1" | "mp4v", _) => 78,
                        _ => 0,
                    };
                    next.push((b.start + b.header + skip, b.end));
                }
            }
        }
        level = next;
    }
    level.into_iter().map(|(from, to)| &data[from..to]).collect()
}
