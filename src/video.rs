//! Spherical video metadata in MP4 (issue 18, `render --video`): Google's Spherical Video V2
//! boxes, which YouTube and 360° players read, added to the video track's sample entry (e.g.
//! `avc1`) of a file an encoder wrote:
//!
//! - `st3d` (full box): stereo mode, 0 mono, 1 top-bottom (left eye on top), 2 left-right;
//! - `sv3d` (container): `svhd` (full box: the metadata source, a NUL-terminated string) and
//!   `proj` (container): `prhd` (full box: pose yaw, pitch, roll as 16.16 fixed point, all 0)
//!   and `equi` (full box: the projection bounds top, bottom, left, right, all 0: the whole
//!   sphere).
//!
//! Every box around the sample entry (`stsd`, `stbl`, `minf`, `mdia`, `trak`, `moov`) grows by
//! the bytes added; where `moov` comes before the media data (`faststart`), every chunk offset
//! (`stco`, `co64`) moves by the same amount.

use crate::error::{Error, Result};

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

/// The `st3d` and, for an equirectangular panorama, `sv3d` boxes.
pub fn spherical_boxes(stereo: StereoMode, equirect: bool) -> Vec<u8> {
    let mut out = full_box(b"st3d", &[stereo as u8]);
    if equirect {
        let svhd = full_box(b"svhd", b"twister\0");
        let prhd = full_box(b"prhd", &[0; 12]);
        let equi = full_box(b"equi", &[0; 16]);
        out.extend(container(b"sv3d", &[svhd, container(b"proj", &[prhd, equi])]));
    }
    out
}

/// `mp4` (named `name` in errors) with the spherical boxes added to its video track's first
/// sample entry.
pub fn with_spherical_metadata(mp4: &[u8], name: &str, stereo: StereoMode, equirect: bool) -> Result<Vec<u8>> {
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
    let added = spherical_boxes(stereo, equirect);
    let grow = added.len();
    let mut out = Vec::with_capacity(mp4.len() + grow);
    out.extend_from_slice(&mp4[..entry.end]);
    out.extend_from_slice(&added);
    out.extend_from_slice(&mp4[entry.end..]);
    // Every box holding the entry grows (32-bit sizes; a 64-bit one keeps its place).
    for b in [moov, trak, mdia, minf, stbl, stsd, entry] {
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
        let moov_end = moov.end + grow;
        let traks = boxes(&out, moov.start + moov.header, moov_end).ok_or_else(|| bad("a broken moov box"))?;
        for trak in traks.iter().filter(|b| &b.kind == b"trak") {
            let stbl = child(&out, trak, b"mdia")
                .and_then(|m| child(&out, &m, b"minf"))
                .and_then(|m| child(&out, &m, b"stbl"))
                .ok_or_else(|| bad("a track without a sample table"))?;
            for table in boxes(&out, stbl.start + stbl.header, stbl.end).ok_or_else(|| bad("a broken stbl box"))? {
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
    }
    Ok(out)
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
