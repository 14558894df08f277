//! The command line's CAVE (`--panorama cave --cave FILE.json`): the walls of the file, each
//! checked and turned into the projection that draws it (`core::panoramas::cave` has the maths), and the
//! settings of one wall's draw.

use twister::core::panoramas::cave::NamedWall;
use twister::core::panoramas::projection::PanoramaKind;
use twister::error::{Error, Result};
use twister::{Projection, RenderSettings};

use crate::args::{RenderArgs, ViewArgs, Viewer};
use glam::Vec3;
use twister::core::scenes::timeline::Timeline;

/// `settings` drawing CAVE wall `wall` (a projection of `ViewArgs::cave_walls`): its size and
/// rectangle, the rest as `settings` have them (placed with the scene).
pub fn on_wall(settings: RenderSettings, wall: &Projection) -> RenderSettings {
    settings.with_projection(Projection {
        width: wall.width,
        height: wall.height,
        wall: wall.wall,
        ..*settings.projection()
    })
}

impl ViewArgs {
    /// `--cave`'s walls, read and checked, for the CAVE panorama (none for the others, which
    /// refuse `--cave`); the CAVE's conditions: its head, no --width/--height, the display's
    /// centre a place.
    pub fn cave_file(&self, panorama: PanoramaKind) -> Result<Vec<NamedWall>> {
        if panorama != PanoramaKind::Cave {
            if self.cave.is_some() {
                return Err(Error::option("--cave", "gives the walls of --panorama cave"));
            }
            return Ok(Vec::new());
        }
        let Some(path) = &self.cave else {
            return Err(Error::option("--cave", "--panorama cave draws the walls of a --cave FILE.json"));
        };
        if self.width.is_some() || self.height.is_some() {
            return Err(Error::option("--width/--height", "a CAVE's walls give their own pixels (--cave)"));
        }
        if matches!(self.viewer, Viewer::Camera(_)) {
            return Err(Error::option("--viewer", "a CAVE's walls and head are in the scene: give --viewer x,y,z"));
        }
        twister::core::panoramas::cave::read_cave(path).map_err(crate::flags::for_user)
    }

    /// Each wall of `--cave` drawn with `settings` (which draw the first): its name and its
    /// projection, checked.
    pub fn cave_walls(&self, settings: &RenderSettings) -> Result<Vec<(String, Projection)>> {
        let walls = self.cave_file(settings.projection().panorama)?;
        walls
            .iter()
            .map(|w| {
                let wall = w.in_display(self.scale, settings.view.viewer, settings.view.yaw_deg);
                let projection =
                    Projection { width: w.pixels[0], height: w.pixels[1], wall: Some(wall), ..*settings.projection() };
                projection.validate().map_err(|e| crate::flags::for_user(crate::flags::name_wall(e, &w.name)))?;
                Ok((w.name.clone(), projection))
            })
            .collect()
    }
}

/// The rows of a `--head-path` file, checked.
pub fn read_head_timeline(path: &std::path::Path) -> Result<Timeline> {
    Timeline::read(path, "head_path", (3, 4), "time,x,y,z[,yaw]", |v| {
        let max = twister::core::scenes::scene::MAX_COORDINATE;
        (v[..3].iter().any(|c| c.abs() > max)).then(|| format!("coordinates within ±{max:e}"))
    })
}

/// The head where a CAVE sequence's `--head-path` starts (at its frame range's first time), for
/// the base settings (each frame then puts the path's head); None unless the CAVE is drawn with
/// a head path and no `--head`.
pub fn cave_head_start(args: &RenderArgs) -> Result<Option<(Vec3, Option<f32>)>> {
    let (Some(path), None, Some(PanoramaKind::Cave)) = (&args.head_path, args.view.head, args.view.panorama) else {
        return Ok(None);
    };
    let first = args.frames.map_or(0, |(a, _)| a);
    let v = read_head_timeline(path)?.at(first as f32 / args.fps);
    Ok(Some((Vec3::new(v[0], v[1], v[2]), v.get(3).copied())))
}
