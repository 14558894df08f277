//! The command line's CAVE (`--panorama cave --cave FILE.json`): the walls of the file, each
//! checked and turned into the projection that draws it (`core::cave` has the maths), and the
//! settings of one wall's draw.

use twister::core::cave::NamedWall;
use twister::core::projection::PanoramaKind;
use twister::error::{Error, Result};
use twister::{Projection, RenderSettings};

use crate::args::{ViewArgs, Viewer};

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

/// A CAVE wall's error with the wall named.
pub(crate) fn name_wall(error: Error, wall: &str) -> Error {
    match error {
        Error::Setting { setting: "view.projection.wall", message } => {
            Error::Setting { setting: "view.projection.wall", message: format!("wall {wall:?}: {message}") }
        }
        other => other,
    }
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
        twister::core::cave::read_cave(path).map_err(crate::flags::for_user)
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
                projection.validate().map_err(|e| crate::flags::for_user(name_wall(e, &w.name)))?;
                Ok((w.name.clone(), projection))
            })
            .collect()
    }
}
