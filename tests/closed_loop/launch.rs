//! What the closed loop takes from a mission's launch file, as the supervisor would hand it to
//! each service: the world and seed, the sonar's panic-stop distance, the camera's frame rate,
//! who gets the launch file's movers and the camera's seed.

use std::path::{Path, PathBuf};

use harvey_geometry::Pose2;

/// One mission's launch settings.
#[derive(Debug, Clone)]
pub struct Launch {
    pub file: PathBuf,
    pub world: PathBuf,
    pub seed: u64,
    /// `sonar --panic-stop-ft` (the service's default: 2 ft).
    pub panic_stop_ft: f64,
    /// `camera --every` (default 2) and `--seed` (default 1).
    pub camera_every: u64,
    pub camera_seed: u64,
    /// Whether the simulator and the camera are given the launch file's `[[mover]]`s.
    pub sim_movers: bool,
    pub camera_movers: bool,
    /// The simulator's and the UMS's `--start` (the mission's own start), if given.
    pub sim_start: Option<Pose2>,
    pub ums_start: Option<Pose2>,
}

/// The arguments of service `name`, with `${seed}` put in.
fn args(doc: &toml::Table, name: &str, seed: u64) -> Vec<String> {
    let services = doc.get("service").and_then(|s| s.as_array()).cloned().unwrap_or_default();
    let service = services.iter().find(|s| s.get("name").and_then(|n| n.as_str()) == Some(name));
    let list = service.and_then(|s| s.get("args")).and_then(|a| a.as_array()).cloned().unwrap_or_default();
    list.iter().filter_map(|a| a.as_str()).map(|a| a.replace("${seed}", &seed.to_string())).collect()
}

/// The value after `flag` in `args`.
fn value(args: &[String], flag: &str) -> Option<String> {
    args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1)).cloned()
}

impl Launch {
    /// Reads `missions/NAME.toml` of the repository.
    pub fn read(name: &str) -> Launch {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("missions").join(format!("{name}.toml"));
        let text = std::fs::read_to_string(&file).expect("the launch file");
        let doc: toml::Table = toml::from_str(&text).expect("TOML");
        let launch = doc.get("launch").and_then(|l| l.as_table()).expect("[launch]");
        let world = launch.get("world").and_then(|w| w.as_str()).expect("[launch] world");
        let seed = launch.get("seed").and_then(|s| s.as_integer()).unwrap_or(1) as u64;
        let (sonar, camera, sim) =
            (args(&doc, "sonar", seed), args(&doc, "camera", seed), args(&doc, "sim-drv", seed));
        let start = |a: &[String]| value(a, "--start").map(|v| v.parse::<Pose2>().expect("a pose"));
        let number = |a: &[String], flag: &str, default: f64| {
            value(a, flag).map_or(default, |v| v.parse().expect("a number"))
        };
        Launch {
            world: file.parent().expect("a folder").join(world),
            seed,
            panic_stop_ft: number(&sonar, "--panic-stop-ft", 2.0),
            camera_every: number(&camera, "--every", 2.0) as u64,
            camera_seed: number(&camera, "--seed", 1.0) as u64,
            sim_movers: sim.iter().any(|a| a == "--movers"),
            camera_movers: camera.iter().any(|a| a == "--movers"),
            sim_start: start(&sim),
            ums_start: start(&args(&doc, "ums", seed)),
            file,
        }
    }

    /// The world as a service loads it: with the poles placed by `poles_seed`, the launch
    /// file's movers and another start, when asked for.
    /// The world file as the robot's map (`sim_seed` None), or as built for the simulator's run
    /// of `sim_seed`, its poles placed.
    pub fn world(&self, sim_seed: Option<u64>, movers: bool, start: Option<Pose2>) -> harvey_world::World {
        let mut w = harvey_world::World::load(&self.world).expect("the world");
        if let Some(seed) = sim_seed {
            w = w.as_built(seed);
        }
        if let Some(s) = start {
            w.start = s;
        }
        if let Some(seed) = sim_seed {
            w.place_poles(seed).expect("room for the poles");
        }
        if movers {
            w.add_movers(harvey_world::load_movers(&self.file).expect("the movers"));
        }
        w
    }
}
