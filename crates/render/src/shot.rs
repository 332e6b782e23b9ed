//! A frame as the simulated camera takes it: one image from the mount, or a stereo pair (003)
//! from two cameras either side of it, each rendered and then given the camera's imperfections,
//! written into one buffer (the loaned shared-memory slice) in the frame's layout.

use harvey_msgs::FrameHeader;
use harvey_world::{Pose2, World};

use crate::{Effects, RenderError, Renderer};

/// The right image's noise is drawn as frame `seq ^ RIGHT_VIEW` (the left image's as `seq`).
const RIGHT_VIEW: u64 = 1 << 63;

/// The renderer, its effects and, for a stereo pair, the distance between its cameras.
#[derive(Debug)]
pub struct Shooter {
    pub renderer: Renderer,
    pub effects: Effects,
    pub baseline_m: Option<f64>,
}

impl Shooter {
    /// How many images a frame holds.
    pub fn views(&self) -> u32 {
        if self.baseline_m.is_some() { 2 } else { 1 }
    }

    /// Bytes of one frame (every view).
    pub fn frame_bytes(&self) -> usize {
        self.renderer.frame_bytes() * self.views() as usize
    }

    /// The header of frame `seq` taken at `stamp_ns`.
    pub fn header(&self, seq: u64, stamp_ns: u64) -> FrameHeader {
        let r = &self.renderer;
        let one = FrameHeader::new(seq, stamp_ns, r.width_px(), r.height_px(), r.encoding());
        FrameHeader { views: self.views(), ..one }
    }

    /// Renders frame `seq` from `pose` at `stamp_ns` into `pixels` ([`Shooter::frame_bytes`]
    /// long): the camera at the mount, or the pair centred on it, the left image first.
    pub fn take(
        &mut self,
        world: &World,
        pose: Pose2,
        seq: u64,
        stamp_ns: u64,
        pixels: &mut [u8],
    ) -> Result<(), RenderError> {
        let needed = self.frame_bytes();
        if pixels.len() != needed {
            return Err(RenderError::BufferSize { len: pixels.len(), needed });
        }
        let r = &self.renderer;
        let (w, h) = (r.width_px() as usize, r.height_px() as usize);
        let bpp = r.encoding().bytes_per_pixel() as usize;
        let views: &[(f64, u64)] = match self.baseline_m {
            Some(b) => &[(b / 2.0, seq), (-b / 2.0, seq ^ RIGHT_VIEW)],
            None => &[(0.0, seq)],
        };
        for (view, (side, noise_seq)) in pixels.chunks_exact_mut(r.frame_bytes()).zip(views) {
            self.renderer.render(world, pose.sideways(*side), view)?;
            self.effects.apply_at(w, h, bpp, *noise_seq, stamp_ns, view);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::Encoding;

    #[test]
    fn a_pair_is_two_renders_from_either_side_of_the_mount() {
        let text = include_str!("../../../worlds/room.toml");
        let w = harvey_world::load_str(text, "room").expect("loads");
        let b = w.camera.stereo_baseline_m.expect("the room has a stereo rig");
        let renderer = || Renderer::new(&w, 64, 48, Encoding::Mono8);
        let mut pair = Shooter { renderer: renderer(), effects: Effects::none(), baseline_m: Some(b) };
        let header = pair.header(3, 9);
        assert_eq!((header.views(), header.payload_len()), (2, pair.frame_bytes()));
        let mut px = vec![0u8; pair.frame_bytes()];
        let pose = Pose2::new(1.0, 3.0, 0.1);
        pair.take(&w, pose, 3, 9, &mut px).expect("takes");
        let one = |side: f64| {
            let mut v = vec![0u8; 64 * 48];
            renderer().render(&w, pose.sideways(side), &mut v).expect("renders");
            v
        };
        assert_eq!(header.view(&px, 0), Some(&one(b / 2.0)[..]), "the left camera is left of the mount");
        assert_eq!(header.view(&px, 1), Some(&one(-b / 2.0)[..]));
        assert_ne!(one(b / 2.0), one(-b / 2.0), "the two views differ");
        let short = pair.take(&w, pose, 3, 9, &mut px[1..]).expect_err("short");
        assert_eq!(short, RenderError::BufferSize { len: 2 * 64 * 48 - 1, needed: 2 * 64 * 48 });
        let mut mono = Shooter { renderer: renderer(), effects: Effects::none(), baseline_m: None };
        let mut px = vec![0u8; mono.frame_bytes()];
        mono.take(&w, pose, 3, 9, &mut px).expect("takes");
        assert_eq!(px, one(0.0), "one camera at the mount");
        assert_eq!(mono.header(3, 9).views(), 1);
    }
}
