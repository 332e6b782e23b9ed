//! Panic-avoid through noisy, quantised sonar, over many draws of the noise: a step onto a
//! nearer surface while driving is no approach, an object coming at the robot is.

#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use super::tests::{P, odo, ring};
use super::*;

/// What sensor 0 sees while the robot drives at 0.3 m/s.
#[derive(Clone, Copy)]
enum Scene {
    /// A still surface 4 m ahead; at the ninth reading the beam slides off it onto one this
    /// much nearer (a door's jamb), under the step that restarts a window.
    Step(f64),
    /// An object coming at the robot at this speed (m/s) from 5 m.
    Object(f64),
}

/// Draws of uniform range noise of +-`amp` m, the readings quantised to tenths of a foot as
/// the Denning's are; for each draw, the range at which the reflex fired, if it did before the
/// range fell under 0.7 m (the panic-stop's 0.61 m and a reading).
fn draws(scene: Scene, amp: f64, n: u64) -> Vec<Option<f64>> {
    let tenth_ft = |m: f64| ((m / 0.03048).round() * 0.03048) as f32;
    (1..=n)
        .map(|draw| {
            let mut seed = 0x2545_f491_4f6c_dd1d_u64.wrapping_mul(draw);
            let mut noise = move || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                ((seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * amp
            };
            let mut a = PanicAvoid::new(P);
            for k in 0..40 {
                let t = 0.15 * f64::from(k);
                let range = match scene {
                    Scene::Step(s) => 4.0 - 0.3 * t - if k < 8 { 0.0 } else { s },
                    Scene::Object(v) => 5.0 - (0.3 + v) * t,
                };
                if range < 0.7 {
                    break;
                }
                a.on_odometry(&odo(t, 0.3 * t, true, 1));
                if a.on_ring(&ring(t, tenth_ft(range + noise()), 2.0, 2.0)).is_some() {
                    return Some(range);
                }
            }
            None
        })
        .collect()
}

#[test]
fn a_step_onto_a_nearer_surface_is_no_approach() {
    // Every window holding the step fits a steep approach (a 0.28 m step in 0.15 s), and a
    // window of four holds it for three readings, as many as confirm: before the streak had
    // to keep closing, this fired in every noiseless draw, 30 % of the draws at +-2.5 cm and
    // 16 % at +-5 cm.
    for step in [0.2, 0.25, 0.28] {
        for amp in [0.0, 0.025] {
            let fired = draws(Scene::Step(step), amp, 200).iter().filter(|f| f.is_some()).count();
            assert_eq!(fired, 0, "step {step} m, noise +-{amp} m");
        }
    }
    // At harsh's noise (+-5 cm, sd 2.9 cm) a streak of noise could keep closing by chance (in
    // none of another 1000 draws; 3 of 1000 at +-8 cm); before, 16 % of the draws fired.
    let fired = draws(Scene::Step(0.28), 0.05, 400).iter().filter(|f| f.is_some()).count();
    assert!(fired <= 4, "{fired} of 400 draws fired");
}

#[test]
fn an_object_bearing_down_through_noise_is_confirmed_in_time() {
    // Coming at 0.6 m/s while the robot drives at 0.3 m/s, the time to contact is under 4 s
    // from 3.6 m on (0.135 m a reading); three readings confirm it from 3.3 m on.
    for amp in [0.0, 0.025, 0.05] {
        let mut at = Vec::new();
        for (draw, f) in draws(Scene::Object(0.6), amp, 200).into_iter().enumerate() {
            let range = f.unwrap_or_else(|| panic!("noise +-{amp} m, draw {draw}: never fired"));
            assert!(range > 2.2, "noise +-{amp} m, draw {draw}: fired with the object {range:.2} m away");
            at.push(range);
        }
        at.sort_by(f64::total_cmp);
        assert!(at[at.len() / 2] > 3.0, "noise +-{amp} m: median range at firing {:.2} m", at[at.len() / 2]);
    }
    // A slow object (0.3 m/s, 2.4 m at 4 s): the streak's closure is within the noise, and
    // in a few draws of harsh's the panic-stop, not the evasion, is what stops the robot.
    let slow = draws(Scene::Object(0.3), 0.05, 400);
    let missed = slow.iter().filter(|f| f.is_none()).count();
    assert!(missed <= 12, "{missed} of 400 draws never fired");
    let mut at: Vec<f64> = slow.into_iter().flatten().collect();
    at.sort_by(f64::total_cmp);
    assert!(at[at.len() / 2] > 1.8, "median range at firing {:.2} m", at[at.len() / 2]);
}
