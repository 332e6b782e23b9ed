//! The set-up's tests: each mode from a small mission, and the errors that name the mission file
//! and the key when the world or the acceptor lacks what the mission names.

use std::path::PathBuf;

use harvey_msgs::MissionState;
use harvey_world::World;

use super::{SetupError, executive};
use crate::behaviours::Behaviour;
use crate::mission::parse;
use crate::{Executive, Mode};

fn world(name: &str) -> World {
    let path = format!("{}/../../worlds/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    World::load(std::path::Path::new(&path)).expect("world")
}

/// A launch file in `missions/` (it need not exist: acceptors are found next to it).
fn file() -> PathBuf {
    PathBuf::from(format!("{}/../../missions/t.toml", env!("CARGO_MANIFEST_DIR")))
}

fn build(text: &str, world: Option<&World>) -> Result<Executive, SetupError> {
    let f = file();
    let m = parse(text, &f.display().to_string()).expect("the mission parses");
    executive(&m, &f, world, 1)
}

const HEAD: &str = "[mission]\ndescription = \"t\"\ntimeout_s = 60\n";

const SERVOED: &str = "[[mission.step]]\nmove_m = 2.0\nincrement_m = 0.6\nservo_landmark = \"exit-sign\"\n\
                       [mission.servo]\naim_m = 0.6\ntemplate_px = 16\nmin_score = 0.9\n";

const PTRANS: &str = "[mission.ptrans]\nto = \"teds-office\"\ngoal_m = [12.0, 2.5]\ngoal_heading_deg = 60\n\
                      approach_m = 0.4\ndoor_depth_m = 1.0\nmilestone_m = 0.15\ngoal_tolerance_m = 0.0127\n\
                      escalate_m = 0.5\nattempts = 3\nback_off_m = 0.3\n";

/// The docking and pole-hunt tables of the missions in `missions/`.
fn goal_table(mission: &str, table: &str) -> String {
    let path = format!("{}/../../missions/{mission}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("readable");
    let start = text.find(&format!("[mission.{table}]")).expect("the table");
    text[start..].to_owned()
}

fn message(e: &SetupError) -> String {
    e.to_string()
}

#[test]
fn a_script_servoed_on_a_landmark_is_a_script_with_the_landmark_s_vertex() {
    let hallway = world("hallway");
    let e = build(&format!("{HEAD}{SERVOED}"), Some(&hallway)).expect("builds");
    let Mode::Script(s) = &e.mode else { panic!("a script: {:?}", e.mode) };
    assert_eq!((s.steps().len(), e.state()), (1, MissionState::Running));
    // Without the world the landmark cannot be found.
    let err = build(&format!("{HEAD}{SERVOED}"), None).expect_err("no world");
    assert!(
        matches!(&err, SetupError::NoWorld { key, .. } if key == "mission.step[0].servo_landmark"),
        "{err:?}"
    );
    // A landmark the world lacks: the file, the key and the name.
    let err = build(&format!("{HEAD}{}", SERVOED.replace("exit-sign", "fire-alarm")), Some(&hallway))
        .expect_err("no such landmark");
    let text = message(&err);
    assert!(text.starts_with(&file().display().to_string()), "{text}");
    assert!(
        text.contains("mission.step[0].servo_landmark: no landmark fire-alarm in world hallway"),
        "{text}"
    );
}

#[test]
fn a_ptrans_goal_is_plan_and_monitor_in_a_world_with_its_locale() {
    let hallway = world("hallway");
    let e = build(&format!("{HEAD}{PTRANS}"), Some(&hallway)).expect("builds");
    let Mode::Plan(p) = &e.mode else { panic!("a plan: {:?}", e.mode) };
    assert!(p.script.steps().is_empty(), "plan-and-monitor makes every step");
    assert_eq!(p.monitor.goal_pose().x_m, 12.0);
    let err = build(&format!("{HEAD}{}", PTRANS.replace("teds-office", "attic")), Some(&hallway))
        .expect_err("no such locale");
    assert!(matches!(&err, SetupError::NoLocale { locale, .. } if locale == "attic"), "{err:?}");
    assert!(message(&err).contains("mission.ptrans.to: locale attic, which world hallway lacks"), "{err}");
    let err = build(&format!("{HEAD}{PTRANS}"), None).expect_err("no world");
    assert!(message(&err).contains("[mission.ptrans] needs the world"), "{err}");
}

#[test]
fn docking_and_the_pole_hunt_are_sequenced_behaviours_with_their_acceptors() {
    let dock = world("dock");
    let e = build(&format!("{HEAD}{}", goal_table("docking", "docking")), Some(&dock)).expect("builds");
    let Mode::Sequenced(run) = &e.mode else { panic!("a behaviour: {:?}", e.mode) };
    let Behaviour::Docking(d) = &run.behaviour else { panic!("docking") };
    assert_eq!(d.seq.fsa.name, "docking");
    // The dock's final pose: 0.5 m out from the face at (13.6, 0), facing it.
    assert!((d.goal_pose().x_m - 13.1).abs() < 1e-12);

    let arena = world("arena");
    let poles = goal_table("poles", "poles");
    let e = build(&format!("{HEAD}{poles}"), Some(&arena)).expect("builds");
    let Mode::Sequenced(run) = &e.mode else { panic!("a behaviour: {:?}", e.mode) };
    let Behaviour::Poles(h) = &run.behaviour else { panic!("the pole hunt") };
    assert!(h.visited.is_empty() && h.seq.fsa.name == "move-to-pole", "{}", h.seq.fsa.name);
    // A world without poles to hunt.
    let err = build(&format!("{HEAD}{poles}"), Some(&world("hallway"))).expect_err("no poles");
    assert!(message(&err).contains("mission.poles: world hallway has no [poles]"), "{err}");
}

#[test]
fn an_acceptor_without_the_named_state_or_file_is_refused_naming_the_key() {
    let dock = world("dock");
    let table = goal_table("docking", "docking");
    let err = build(
        &format!("{HEAD}{}", table.replace("docked_state = \"q4\"", "docked_state = \"q9\"")),
        Some(&dock),
    )
    .expect_err("no state q9");
    assert!(
        matches!(&err, SetupError::NoState { key, state, .. } if key == "mission.docking.docked_state" && state == "q9"),
        "{err:?}"
    );
    let err = build(&format!("{HEAD}{}", table.replace("fsa/docking.toml", "fsa/missing.toml")), Some(&dock))
        .expect_err("no file");
    assert!(matches!(&err, SetupError::ReadAcceptor { key, .. } if key == "mission.docking.fsa"), "{err:?}");
    assert!(message(&err).contains("fsa/missing.toml"), "{err}");
    let err = build(&format!("{HEAD}{table}"), None).expect_err("no world");
    assert!(matches!(&err, SetupError::NoWorld { key, .. } if key == "[mission.docking]"), "{err:?}");
}
