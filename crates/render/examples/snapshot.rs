//! Renders one camera frame of a world from a pose to a PNG, for looking at a world by eye:
//! `cargo run --release -p harvey-render --example snapshot -- worlds/hallway.toml 0,0,0 out.png [rgb8]`
//! (pose `x_m,y_m,heading_deg`).

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_world::Pose2;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    anyhow::ensure!(args.len() >= 3, "usage: snapshot WORLD x,y,heading_deg OUT.png [mono8|rgb8]");
    let world = harvey_world::World::load(std::path::Path::new(&args[0]))?;
    let p: Vec<f64> = args[1].split(',').map(str::parse).collect::<Result<_, _>>()?;
    anyhow::ensure!(p.len() == 3, "pose is x_m,y_m,heading_deg");
    let encoding = Encoding::parse(args.get(3).map_or("mono8", String::as_str))
        .ok_or_else(|| anyhow::anyhow!("encoding"))?;
    let (w, h) = (world.camera.width_px, world.camera.height_px);
    let mut r = Renderer::new(&world, w, h, encoding);
    let mut px = vec![0u8; r.frame_bytes()];
    r.render(&world, Pose2::from_degrees(p[0], p[1], p[2]), &mut px)?;
    match encoding {
        Encoding::Mono8 => image::GrayImage::from_raw(w, h, px).map(|i| i.save(&args[2])),
        Encoding::Rgb8 => image::RgbImage::from_raw(w, h, px).map(|i| i.save(&args[2])),
    }
    .ok_or_else(|| anyhow::anyhow!("buffer size"))??;
    Ok(())
}
