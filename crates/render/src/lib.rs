//! The camera's renderer: ray casting the world's walls and floor from a pose through a pinhole
//! camera, pixel = illumination x reflectance, written straight into the caller's buffer (the
//! loaned shared-memory slice); `Shooter` a whole frame, one camera's or a stereo pair's.

mod blur;
mod contrast;
mod effects;
mod shot;

pub use contrast::{CONTRAST_BANDS, edge_contrast};
pub use effects::{Effects, mount_error};
use harvey_msgs::Encoding;
use harvey_world::{Pose2, World};
pub use shot::Shooter;

/// Why a frame could not be rendered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// The caller's buffer is not [`Renderer::frame_bytes`] long.
    #[error("frame buffer is {len} bytes, {needed} needed")]
    BufferSize { len: usize, needed: usize },
    /// The pose holds a NaN or an infinity (shown as `[x, y, heading]`).
    #[error("pose {:?} is not finite", [.pose.x_m, .pose.y_m, .pose.heading_rad])]
    NotFinite { pose: Pose2 },
}

/// One image column's ray: its direction and the walls it meets.
#[derive(Debug, Clone, Default)]
struct Column {
    dir: [f64; 2],
    cos_off_axis: f64,
    /// Depth along the optical axis of each wall the ray meets, nearest first, with the wall
    /// and the position along it: a row whose ray passes over a wall sees what is behind.
    walls: Vec<(f64, usize, f64)>,
}

/// Renders frames of one size; keeps its per-column scratch so frames allocate nothing.
#[derive(Debug)]
pub struct Renderer {
    width_px: u32,
    height_px: u32,
    encoding: Encoding,
    focal_px: f64,
    /// The camera's true yaw (left positive) and pitch (down positive) on its mount, radians:
    /// what the robot's calibration does not know (`Camera::misalignment_sd_rad`).
    yaw_rad: f64,
    pitch_rad: f64,
    columns: Vec<Column>,
    hits: Vec<harvey_world::Hit>,
}

impl Renderer {
    /// A renderer for `width_px x height_px`; the world's focal length scales with the width.
    pub fn new(world: &World, width_px: u32, height_px: u32, encoding: Encoding) -> Self {
        let focal_px = world.camera.focal_for(width_px);
        Self {
            width_px,
            height_px,
            encoding,
            focal_px,
            yaw_rad: 0.0,
            pitch_rad: 0.0,
            columns: vec![Column::default(); width_px as usize],
            hits: Vec::new(),
        }
    }

    /// The same renderer with the camera turned `yaw_rad` left and tilted `pitch_rad` down on
    /// its mount (small angles: the pitch moves every row by the same angle).
    pub fn misaligned(self, yaw_rad: f64, pitch_rad: f64) -> Self {
        Self { yaw_rad, pitch_rad, ..self }
    }

    /// The mount's yaw and pitch, radians.
    pub fn misalignment(&self) -> (f64, f64) {
        (self.yaw_rad, self.pitch_rad)
    }

    pub fn frame_bytes(&self) -> usize {
        (self.width_px * self.height_px * self.encoding.bytes_per_pixel()) as usize
    }

    pub fn width_px(&self) -> u32 {
        self.width_px
    }

    pub fn height_px(&self) -> u32 {
        self.height_px
    }

    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// Renders the view from `pose` into `out` (exactly `frame_bytes()` long).
    pub fn render(&mut self, world: &World, pose: Pose2, out: &mut [u8]) -> Result<(), RenderError> {
        if out.len() != self.frame_bytes() {
            return Err(RenderError::BufferSize { len: out.len(), needed: self.frame_bytes() });
        }
        let Pose2 { x_m: x, y_m: y, heading_rad: heading } = pose;
        if !(x.is_finite() && y.is_finite() && heading.is_finite()) {
            return Err(RenderError::NotFinite { pose });
        }
        let cx = f64::from(self.width_px) / 2.0;
        let aimed = Pose2 { heading_rad: heading + self.yaw_rad, ..pose };
        for (u, col) in self.columns.iter_mut().enumerate() {
            col.cast(world, aimed, (cx - u as f64 - 0.5) / self.focal_px, &mut self.hits);
        }
        let cam = &world.camera;
        let cy = f64::from(self.height_px) / 2.0;
        let bpp = self.encoding.bytes_per_pixel() as usize;
        let row_bytes = self.width_px as usize * bpp;
        for (v, row) in out.chunks_exact_mut(row_bytes).enumerate() {
            // Image y of this row over the focal length, down positive, turned by the pitch.
            let level = (v as f64 + 0.5 - cy) / self.focal_px;
            let down = if self.pitch_rad == 0.0 { level } else { (level.atan() + self.pitch_rad).tan() };
            for (col, px) in self.columns.iter().zip(row.chunks_exact_mut(bpp)) {
                let (reflectance, colour) = col.appearance(world, [x, y], down);
                let lit = cam.illumination * reflectance;
                if bpp == 1 {
                    px[0] = lit.round().clamp(0.0, 255.0) as u8;
                } else {
                    for (c, k) in px.iter_mut().zip(colour) {
                        *c = (lit * k).round().clamp(0.0, 255.0) as u8;
                    }
                }
            }
        }
        Ok(())
    }
}

impl Column {
    /// Casts the ray of the image column whose direction is `tan_left` (left positive) off the
    /// axis; `hits` is scratch.
    fn cast(&mut self, world: &World, pose: Pose2, tan_left: f64, hits: &mut Vec<harvey_world::Hit>) {
        let off_axis = tan_left.atan();
        let a = pose.heading_rad + off_axis;
        self.dir = [a.cos(), a.sin()];
        self.cos_off_axis = off_axis.cos();
        world.cast_ray_all([pose.x_m, pose.y_m], self.dir, 1e3, hits);
        self.walls.clear();
        self.walls.extend(hits.iter().map(|h| (h.distance_m * self.cos_off_axis, h.wall, h.along_m)));
    }

    /// Reflectance and colour of what the ray `down` (image y over focal length) below the
    /// axis in this column meets first.
    fn appearance(&self, world: &World, origin: [f64; 2], down: f64) -> (f64, [f64; 3]) {
        appearance(world, origin, self, self.walls.iter().copied(), down)
    }
}

/// Reflectance and colour of what the ray `down` below the axis of `column` meets first among
/// `walls` (depth along the axis, wall, position along it), the floor and the ceiling: the
/// nearest wall met below its top, unless the ray reaches the floor before it. A row whose ray
/// passes over a wall lower than the camera sees what is behind the wall.
fn appearance(
    world: &World,
    origin: [f64; 2],
    column: &Column,
    walls: impl Iterator<Item = (f64, usize, f64)>,
    down: f64,
) -> (f64, [f64; 3]) {
    const WHITE: [f64; 3] = [1.0; 3];
    let h = world.camera.height_m;
    // A wall is met where the ray is between the floor and the wall's top there; a wall met
    // under the floor means the floor came first.
    let seen = walls
        .filter(|&(depth, wall, _)| (0.0..=world.walls[wall].height_m).contains(&(h - down * depth)))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    match seen {
        Some((depth, wall, along)) => world.walls[wall].appearance_at(along, h - down * depth),
        None if down > 0.0 => (floor_at(world, origin, column, h / down), WHITE),
        None => (world.floor.ceiling_reflectance, WHITE),
    }
}

/// The reflectance a ray from the camera at `pose` meets first through image point `(u, v)`
/// (pixels from the top-left corner) of a `width_px x height_px` image: ray tracing one pixel,
/// as appearance templates are built (000 §5.3).
pub fn reflectance_at(world: &World, pose: Pose2, width_px: u32, height_px: u32, u: f64, v: f64) -> f64 {
    let f = world.camera.focal_for(width_px);
    let (cx, cy) = (f64::from(width_px) / 2.0, f64::from(height_px) / 2.0);
    // One ray, so its walls are taken as they come rather than kept: nothing is allocated.
    let off_axis = ((cx - u) / f).atan();
    let a = pose.heading_rad + off_axis;
    let col = Column { dir: [a.cos(), a.sin()], cos_off_axis: off_axis.cos(), walls: Vec::new() };
    let origin = [pose.x_m, pose.y_m];
    let walls =
        world.ray_hits(origin, col.dir, 1e3).map(|h| (h.distance_m * col.cos_off_axis, h.wall, h.along_m));
    appearance(world, origin, &col, walls, (v - cy) / f).0
}

/// Reflectance of the floor tile seen at optical depth `depth_m` along a column.
fn floor_at(world: &World, origin: [f64; 2], col: &Column, depth_m: f64) -> f64 {
    let range = depth_m / col.cos_off_axis;
    let p = [origin[0] + col.dir[0] * range, origin[1] + col.dir[1] * range];
    let t = world.floor.tile_m;
    let parity = ((p[0] / t).floor() as i64 + (p[1] / t).floor() as i64).rem_euclid(2) as usize;
    world.floor_reflectance_at(p[0], p[1])[parity]
}

/// FNV-1a over a frame: a cheap fingerprint to compare frames across processes.
pub fn checksum(pixels: &[u8]) -> u64 {
    pixels.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hallway() -> World {
        harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
    }

    #[test]
    fn walls_floor_and_ceiling_have_their_reflectances() {
        let w = hallway();
        let mut r = Renderer::new(&w, 640, 480, Encoding::Mono8);
        let mut img = vec![0u8; r.frame_bytes()];
        r.render(&w, Pose2::new(5.0, 0.0, 0.0), &mut img).expect("renders");
        let at = |u: usize, v: usize| img[v * 640 + u];
        let lit = |refl: f64| (w.camera.illumination * refl).round() as u8;
        // The end wall straight ahead, 11 m away, at camera height: the row through the centre.
        assert_eq!(at(320, 240), lit(0.60));
        // The top row looks at the ceiling, the bottom row at the floor tiles.
        assert_eq!(at(320, 0), lit(w.floor.ceiling_reflectance));
        assert!([lit(0.55), lit(0.40)].contains(&at(320, 479)));
        // The left edge column looks at the left wall (reflectance 0.70) near camera height, 7.7 m
        // along it, clear of its doors; its door at 4.0-4.9 m is darker (0.30) when seen from x = 2.
        assert_eq!(at(0, 240), lit(0.70));
        // From x = 2 the column through the middle of the lab's doorway (x = 4.45 on the north
        // wall) sees through the opening to the lab's east wall (reflectance 0.50).
        r.render(&w, Pose2::new(2.0, 0.0, 0.0), &mut img).expect("renders");
        let f = w.camera.focal_px;
        let u = (320.0 - f * (1.0 / 2.45) - 0.5).round() as usize;
        assert_eq!(img[240 * 640 + u], lit(0.50), "column {u}");
    }

    #[test]
    fn rows_passing_over_a_low_box_see_what_is_behind_it() {
        let w = harvey_world::load_str(include_str!("../../../worlds/arena.toml"), "arena").expect("loads");
        let mut r = Renderer::new(&w, 640, 480, Encoding::Mono8);
        let mut img = vec![0u8; r.frame_bytes()];
        // 1.7 m south of the cardboard box (0.7 m tall, faces at y = 7.7 and 8.3), facing north
        // towards the arena's wall at y = 12 (2 m tall).
        r.render(&w, Pose2::new(4.0, 6.0, std::f64::consts::FRAC_PI_2), &mut img).expect("renders");
        let lit = |refl: f64| (w.camera.illumination * refl).round() as u8;
        let at = |v: usize| img[v * 640 + 320];
        // Row 420 meets the box's face 0.65 m up; row 300 passes over the box and meets the far
        // wall 0.55 m up (it showed the ceiling before); row 380 passes over the box's near
        // face, and its far face, seen from above, stands for the lid.
        assert_eq!(at(420), lit(0.42));
        assert_eq!(at(300), lit(0.50));
        assert_eq!(at(380), lit(0.42));
        // Row 355 passes over the box and reaches the floor before the far wall.
        let f = w.camera.focal_px;
        let floor_depth = w.camera.height_m / ((355.5 - 240.0) / f);
        assert!(floor_depth > 2.3 && floor_depth < 6.0, "{floor_depth}");
        assert!(w.floor.reflectance.iter().any(|&k| at(355) == lit(k)), "{}", at(355));
    }

    #[test]
    fn a_misaligned_mount_turns_and_tilts_the_view() {
        let w = hallway();
        let (mut a, mut b) = (vec![0u8; 640 * 480], vec![0u8; 640 * 480]);
        let pose = Pose2::new(5.0, 0.0, 0.0);
        Renderer::new(&w, 640, 480, Encoding::Mono8)
            .misaligned(0.01, 0.0)
            .render(&w, pose, &mut a)
            .expect("renders");
        Renderer::new(&w, 640, 480, Encoding::Mono8)
            .render(&w, Pose2 { heading_rad: 0.01, ..pose }, &mut b)
            .expect("renders");
        assert_eq!(a, b, "a yawed mount sees what a turned robot sees");
        // The end wall's foot (floor below, wall above) in the centre column, 11 m ahead: it sits
        // f h / d = 60 px below the centre row; tilting down by 0.01 rad raises it f 0.01 = 5.5 px.
        let foot =
            |img: &[u8]| (240..480).find(|&v| img[v * 640 + 320] != img[240 * 640 + 320]).expect("a foot");
        let level = foot(&b);
        Renderer::new(&w, 640, 480, Encoding::Mono8)
            .misaligned(0.0, 0.01)
            .render(&w, Pose2 { heading_rad: 0.01, ..pose }, &mut a)
            .expect("renders");
        let tilted = foot(&a);
        assert!((level as f64 - tilted as f64 - 5.54).abs() <= 1.0, "foot at {level}, tilted {tilted}");
    }

    #[test]
    fn colour_images_carry_the_regions_colours() {
        let w = hallway();
        let mut r = Renderer::new(&w, 640, 480, Encoding::Rgb8);
        let mut img = vec![0u8; r.frame_bytes()];
        // Facing the red sign (x 12.2-12.6, z 1.4-1.7 on the north wall) from 1 m in front of it.
        r.render(&w, Pose2::new(12.4, 0.0, std::f64::consts::FRAC_PI_2), &mut img).expect("renders");
        // The sign's centre, 0.35 m above the camera at 1 m: 0.35 x 554 px above the centre row.
        let v = (240.0 - 0.35 * w.camera.focal_px).round() as usize;
        let px = &img[(v * 640 + 320) * 3..(v * 640 + 320) * 3 + 3];
        let lit = w.camera.illumination * 0.95;
        assert_eq!(px, [(lit * 1.0).round() as u8, (lit * 0.35).round() as u8, (lit * 0.3).round() as u8]);
    }

    #[test]
    fn uncoloured_faces_render_grey_in_rgb_and_sizes_are_checked() {
        let w = hallway();
        let mut mono = Renderer::new(&w, 64, 48, Encoding::Mono8);
        let mut rgb = Renderer::new(&w, 64, 48, Encoding::Rgb8);
        let mut a = vec![0u8; mono.frame_bytes()];
        let mut b = vec![0u8; rgb.frame_bytes()];
        // Looking back down the hall at the west end wall: no coloured region in view.
        mono.render(&w, Pose2::new(1.0, 0.2, std::f64::consts::PI), &mut a).expect("renders");
        rgb.render(&w, Pose2::new(1.0, 0.2, std::f64::consts::PI), &mut b).expect("renders");
        assert!(a.iter().zip(b.chunks_exact(3)).all(|(g, p)| p == [*g, *g, *g]));
        let e = mono.render(&w, Pose2::default(), &mut b).expect_err("an rgb8 buffer for mono8");
        assert_eq!(e.to_string(), "frame buffer is 9216 bytes, 3072 needed");
        let e = mono.render(&w, Pose2::new(f64::NAN, 0.0, 0.0), &mut a).expect_err("NaN");
        assert_eq!(e.to_string(), "pose [NaN, 0.0, 0.0] is not finite");
        assert_ne!(checksum(&a), checksum(&a[1..]));
    }
}
