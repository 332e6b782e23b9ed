//! Executing TURN, MOVE and velocity commands with the terrain error model of 002 §3.2
//! (Table 3): the true path loses distance, drifts and skitters; the encoders report the
//! commanded path.

use harvey_world::Terrain;

use harvey_geometry::Rng;

pub use harvey_geometry::{FT, Pose2};

/// A motion under way: where it started, where it will end (true and encoder), how far along.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Motion {
    Move {
        truth0: Pose2,
        enc0: Pose2,
        true_m: f64,
        true_dth: f64,
        commanded_m: f64,
        done: f64,
        duration_s: f64,
    },
    Turn {
        truth0: Pose2,
        enc0: Pose2,
        true_rad: f64,
        skitter_m: f64,
        commanded_rad: f64,
        done: f64,
        duration_s: f64,
    },
    Velocity {
        v_mps: f64,
        w_radps: f64,
        drift_rad_per_m: f64,
    },
}

/// Draws the true outcome of a MOVE of `commanded_m`. The robot never goes further than
/// commanded (002 §3.2).
pub fn plan_move(
    t: &Terrain,
    rng: &mut Rng,
    drift_sign: f64,
    truth0: Pose2,
    enc0: Pose2,
    commanded_m: f64,
    speed_mps: f64,
) -> Motion {
    let ft = commanded_m.abs() / FT;
    let loss_ft = t.translational_loss_ft_per_ft * ft
        + t.inertial_loss_ft
        + rng.normal(0.0, t.translational_sd_ft_per_ft * ft);
    let true_ft = (ft - loss_ft).clamp(0.0, ft);
    let drift_deg = drift_sign * rng.normal(t.drift_deg_per_ft, t.drift_sd_deg_per_ft) * true_ft;
    Motion::Move {
        truth0,
        enc0,
        true_m: true_ft * FT * commanded_m.signum(),
        true_dth: drift_deg.to_radians(),
        commanded_m,
        done: 0.0,
        duration_s: commanded_m.abs() / speed_mps,
    }
}

/// Draws the true outcome of a TURN of `commanded_rad` (counter-clockwise positive).
pub fn plan_turn(
    t: &Terrain,
    rng: &mut Rng,
    truth0: Pose2,
    enc0: Pose2,
    commanded_rad: f64,
    rate_radps: f64,
) -> Motion {
    let deg = commanded_rad.abs().to_degrees();
    let loss = (t.rotational_loss_deg_per_deg + rng.normal(0.0, t.rotational_sd_deg_per_deg)) * deg;
    let true_deg = (deg - loss).clamp(0.0, deg);
    let skitter_ft = rng.normal(t.skitter_ft_per_deg, t.skitter_sd_ft_per_deg).max(0.0) * deg;
    Motion::Turn {
        truth0,
        enc0,
        true_rad: true_deg.to_radians() * commanded_rad.signum(),
        // To the left while turning counter-clockwise, to the right while turning clockwise.
        skitter_m: skitter_ft * FT * commanded_rad.signum(),
        commanded_rad,
        done: 0.0,
        duration_s: commanded_rad.abs() / rate_radps,
    }
}

/// The shaft encoders' resolution: travel and steering per count (0: exact).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counts {
    pub m: f64,
    pub rad: f64,
}

impl Counts {
    /// From the world's `[robot] encoder_count_ft` and `encoder_count_deg`.
    pub fn of(r: &harvey_world::Robot) -> Self {
        Self { m: r.encoder_count_ft * FT, rad: r.encoder_count_deg.to_radians() }
    }
}

/// `x` in whole counts of `count` (towards zero: a count registers once it is complete).
fn counted(x: f64, count: f64) -> f64 {
    if count > 0.0 { (x / count + 1e-9 * x.signum()).trunc() * count } else { x }
}

/// Advances a motion by `dt_s`; returns the new (truth, encoder) poses and whether it finished.
/// The encoders count the commanded motion in whole counts of `counts`.
pub fn advance(
    m: &mut Motion,
    t: &Terrain,
    counts: Counts,
    truth: Pose2,
    enc: Pose2,
    dt_s: f64,
) -> (Pose2, Pose2, bool) {
    match m {
        Motion::Move { truth0, enc0, true_m, true_dth, commanded_m, done, duration_s } => {
            *done = if *duration_s > 0.0 { (*done + dt_s / *duration_s).min(1.0) } else { 1.0 };
            let f = *done;
            let enc = enc0.arc(counted(f * *commanded_m, counts.m), 0.0);
            (truth0.arc(f * *true_m, f * *true_dth), enc, f >= 1.0)
        }
        Motion::Turn { truth0, enc0, true_rad, skitter_m, commanded_rad, done, duration_s } => {
            *done = if *duration_s > 0.0 { (*done + dt_s / *duration_s).min(1.0) } else { 1.0 };
            let f = *done;
            let shifted = truth0.sideways(f * *skitter_m);
            let truth = Pose2 { heading_rad: truth0.heading_rad + f * *true_rad, ..shifted };
            let turned = counted(f * *commanded_rad, counts.rad);
            (truth, Pose2 { heading_rad: enc0.heading_rad + turned, ..*enc0 }, f >= 1.0)
        }
        Motion::Velocity { v_mps, w_radps, drift_rad_per_m } => {
            let s_true = *v_mps * (1.0 - t.translational_loss_ft_per_ft) * dt_s;
            let dth_true =
                *w_radps * (1.0 - t.rotational_loss_deg_per_deg) * dt_s + *drift_rad_per_m * s_true.abs();
            let idle = *v_mps == 0.0 && *w_radps == 0.0;
            (truth.arc(s_true, dth_true), enc.arc(*v_mps * dt_s, *w_radps * dt_s), idle)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tile, from the hallway world's copy of 002 Table 3.
    fn tile() -> Terrain {
        let world = include_str!("../../../worlds/hallway.toml");
        harvey_world::load_str(world, "hallway.toml").expect("hallway loads").terrain["tile"].clone()
    }

    #[test]
    fn a_move_loses_distance_as_table_3_says_and_never_overshoots() {
        let mut rng = Rng::new(11);
        let n = 2000;
        let mut travelled_ft = Vec::new();
        for _ in 0..n {
            let mut m = plan_move(&tile(), &mut rng, 1.0, Pose2::default(), Pose2::default(), 20.0 * FT, 0.3);
            let (truth, enc, finished) =
                advance(&mut m, &tile(), Counts::default(), Pose2::default(), Pose2::default(), 1e6);
            assert!(finished);
            assert!((enc.x_m - 20.0 * FT).abs() < 1e-9, "encoders report the commanded move");
            let d = truth.x_m.hypot(truth.y_m) / FT;
            assert!(d <= 20.0 + 1e-9, "never further than commanded: {d}");
            travelled_ft.push(d);
        }
        let mean = travelled_ft.iter().sum::<f64>() / n as f64;
        // 20 ft at 4.2 % loss plus 0.0084 ft inertial loss; the arc's chord is a hair shorter.
        let expected = 20.0 - 20.0 * 0.042 - 0.0084;
        assert!((mean - expected).abs() < 0.01, "mean {mean} vs {expected}");
    }

    #[test]
    fn the_encoders_count_whole_counts() {
        let counts = Counts { m: 0.01 * FT, rad: 0.1f64.to_radians() };
        let mut rng = Rng::new(2);
        let p = Pose2::default();
        let mut m = plan_move(&tile(), &mut rng, 1.0, p, p, 1.0, 0.3);
        // 0.1 s of a 3.33 s move: 0.03 m = 0.0984 ft, which the encoders count as 0.09 ft.
        let (_, enc, _) = advance(&mut m, &tile(), counts, p, p, 0.1);
        assert!((enc.x_m - 0.09 * FT).abs() < 1e-9, "{}", enc.x_m / FT);
        let mut t = plan_turn(&tile(), &mut rng, p, p, -1.0, 0.5);
        let (_, enc, _) = advance(&mut t, &tile(), counts, p, p, 0.1);
        // -0.05 rad = -2.865 deg: -2.8 deg counted.
        assert!((enc.heading_rad.to_degrees() + 2.8).abs() < 1e-9, "{}", enc.heading_rad.to_degrees());
    }
}
