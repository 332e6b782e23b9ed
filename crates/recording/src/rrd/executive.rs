//! How the executive's own working is drawn: each action-level correction as plots (heading
//! error and turn in degrees, estimated offset from the line in metres) and a log line; each pose
//! refinement as the expected and refined poses in the world view and a log line; the plan sketch
//! as a path through its numbered milestones (solid where primitive, faint where still abstract),
//! its stage as a state lane and each milestone check in the log; a sequenced behaviour's acceptor
//! state as a state lane (each transition in the log) and its motor schemas' vectors as arrows.

use harvey_msgs::{BehaviourState, CheckOutcome, PlanSketch, PoseFix, ServoCorrection};

use super::{RrdError, RrdWriter};

impl RrdWriter {
    pub fn servo(&mut self, c: &ServoCorrection) -> Result<(), RrdError> {
        self.at(c.header.stamp_ns);
        for (path, v) in [
            ("plots/servo/heading_error_deg", c.heading_error_rad.to_degrees()),
            ("plots/servo/correction_deg", c.correction_rad.to_degrees()),
            ("plots/deviation/estimated_m", c.offset_m),
        ] {
            self.rec.log(path, &rerun::Scalars::single(v)).map_err(|e| self.err(e))?;
        }
        let text = format!(
            "servo after increment {}: landmark {} at ({:.1}, {:.1}) px, heading error {:.2} deg, turn {:.2} deg",
            c.increment,
            c.landmark_index,
            c.found_px[0],
            c.found_px[1],
            c.heading_error_rad.to_degrees(),
            c.correction_rad.to_degrees()
        );
        self.say("executive", rerun::TextLogLevel::INFO, text)
    }

    pub fn pose_fix(&mut self, p: &PoseFix) -> Result<(), RrdError> {
        self.at(p.header.stamp_ns);
        let expected = super::pose_arrow(&p.expected, rerun::Color::from_rgb(200, 120, 40));
        self.rec.log("world/pose_fix/expected", &expected).map_err(|e| self.err(e))?;
        let refined = super::pose_arrow(&p.refined, rerun::Color::from_rgb(40, 160, 220));
        self.rec.log("world/pose_fix/refined", &refined).map_err(|e| self.err(e))?;
        let text = format!(
            "pose refined from ({:.3}, {:.3}) to ({:.3}, {:.3}) m, heading {:.2} deg: {} of {} vertices found, {} kept, {:.2} px rms",
            p.expected.x_m,
            p.expected.y_m,
            p.refined.x_m,
            p.refined.y_m,
            p.refined.heading_rad.to_degrees(),
            p.found,
            p.asked,
            p.kept,
            p.rms_px
        );
        self.say("executive", rerun::TextLogLevel::INFO, text)
    }

    pub fn plan(&mut self, p: &PlanSketch) -> Result<(), RrdError> {
        self.at(p.header.stamp_ns);
        let n = (p.place_count as usize).min(harvey_msgs::SKETCH_PLACES);
        let places: Vec<[f32; 2]> =
            (0..n).map(|k| super::up([p.places_m[2 * k], p.places_m[2 * k + 1]])).collect();
        let (mut detailed, mut abstract_) = (Vec::new(), Vec::new());
        for k in 0..n.saturating_sub(1) {
            let leg = vec![places[k], places[k + 1]];
            if p.primitive_mask & (1 << k) != 0 { detailed.push(leg) } else { abstract_.push(leg) }
        }
        let strips = [
            ("world/plan/primitive", detailed, rerun::Color::from_rgb(60, 200, 120)),
            ("world/plan/abstract", abstract_, rerun::Color::from_unmultiplied_rgba(60, 200, 120, 90)),
        ];
        for (path, legs, colour) in strips {
            self.rec
                .log(path, &rerun::LineStrips2D::new(legs).with_colors([colour]))
                .map_err(|e| self.err(e))?;
        }
        let milestones = rerun::Points2D::new(places.iter().skip(1).copied())
            .with_labels((1..n).map(|k| format!("m{k}")))
            .with_radii([0.06])
            .with_colors([rerun::Color::from_rgb(60, 200, 120)]);
        self.rec.log("world/plan/milestones", &milestones).map_err(|e| self.err(e))?;
        self.plan_places = (0..n).map(|k| [p.places_m[2 * k], p.places_m[2 * k + 1]]).collect();
        if self.plan_stage != Some(p.stage) {
            self.plan_stage = Some(p.stage);
            self.lane("plan", format!("stage {}", p.stage))?;
        }
        if p.checks == self.plan_checks || p.last_outcome == 0 {
            return Ok(());
        }
        self.plan_checks = p.checks;
        let (what, level) = match p.last_outcome {
            o if o == CheckOutcome::Reached as u32 => ("reached", rerun::TextLogLevel::INFO),
            o if o == CheckOutcome::Retried as u32 => {
                ("missed: retried from here", rerun::TextLogLevel::WARN)
            }
            _ => ("missed: plan developed afresh", rerun::TextLogLevel::WARN),
        };
        let text = format!(
            "milestone check {}: {what}, {:.3} m off ({} replans)",
            p.checks, p.last_off_m, p.replans
        );
        self.say("executive", level, text)
    }

    pub fn behaviour(&mut self, b: &BehaviourState) -> Result<(), RrdError> {
        self.at(b.header.stamp_ns);
        if self.fsa_state != Some(b.fsa_state) {
            self.fsa_state = Some(b.fsa_state);
            self.lane("acceptor", format!("q{}", b.fsa_state))?;
        }
        // move-to-goal, avoid-static-obstacle, noise, avoid-past, probe, sum; 1 m per 0.1 m/s.
        let colours =
            [(40, 200, 80), (230, 60, 50), (160, 160, 160), (200, 120, 220), (80, 170, 230), (255, 255, 255)];
        let origin = super::up([b.at.x_m, b.at.y_m]);
        let (mut vectors, mut origins, mut cols) = (Vec::new(), Vec::new(), Vec::new());
        for (k, (r, g, bl)) in colours.into_iter().enumerate() {
            let v = [b.vectors_mps[2 * k] * 10.0, b.vectors_mps[2 * k + 1] * 10.0];
            if v[0].hypot(v[1]) > 1e-3 {
                vectors.push(super::up(v));
                origins.push(origin);
                cols.push(rerun::Color::from_rgb(r, g, bl));
            }
        }
        let arrows = rerun::Arrows2D::from_vectors(vectors).with_origins(origins).with_colors(cols);
        self.rec.log("world/robot/schemas", &arrows).map_err(|e| self.err(e))?;
        if b.transitions == self.fsa_transitions {
            return Ok(());
        }
        self.fsa_transitions = b.transitions;
        let trigger = ["normal", "terminal", "recoverable error", "fatal error"]
            .get(b.last_trigger as usize)
            .unwrap_or(&"?");
        let text = format!("{trigger} -> q{} (transition {})", b.fsa_state, b.transitions);
        self.say("acceptor", rerun::TextLogLevel::INFO, text)
    }
}
