//! What Python decoded against what the recording holds, field by field: floats equal (NaN to
//! NaN), integers exactly, each difference kept as a line of the failure message.

use harvey_msgs::{Header, Odometry, Pose2, SonarRing};
use serde_json::Value;

/// A number as the client writes it: non-finite floats are the strings `NaN`, `inf`, `-inf`.
fn num(v: &Value) -> f64 {
    match v {
        Value::Number(n) => n.as_f64().unwrap(),
        Value::String(s) if s == "NaN" => f64::NAN,
        Value::String(s) if s == "inf" => f64::INFINITY,
        Value::String(s) if s == "-inf" => f64::NEG_INFINITY,
        other => panic!("not a number: {other}"),
    }
}

/// Compares what Python decoded with what the recording holds, field by field.
#[derive(Default)]
pub struct Compare {
    pub fields: usize,
    pub mismatches: Vec<String>,
}

impl Compare {
    fn float(&mut self, what: &str, py: &Value, rust: f64) {
        self.fields += 1;
        let p = num(py);
        if !(p == rust || p.is_nan() && rust.is_nan()) {
            self.mismatches.push(format!("{what}: Python {p}, recording {rust}"));
        }
    }

    pub fn int(&mut self, what: &str, py: &Value, rust: u64) {
        self.fields += 1;
        if py.as_u64() != Some(rust) {
            self.mismatches.push(format!("{what}: Python {py}, recording {rust}"));
        }
    }

    fn floats<F: Copy + Into<f64>>(&mut self, what: &str, py: &Value, rust: &[F]) {
        let py = py.as_array().unwrap();
        assert_eq!(py.len(), rust.len(), "{what}");
        for (i, (p, r)) in py.iter().zip(rust).enumerate() {
            self.float(&format!("{what}[{i}]"), p, (*r).into());
        }
    }

    fn header(&mut self, what: &str, py: &Value, h: &Header) {
        self.int(&format!("{what}.seq"), &py["seq"], h.seq);
        self.int(&format!("{what}.stamp_ns"), &py["stamp_ns"], h.stamp_ns);
    }

    fn pose(&mut self, what: &str, py: &Value, p: &Pose2) {
        self.float(&format!("{what}.x_m"), &py["x_m"], p.x_m);
        self.float(&format!("{what}.y_m"), &py["y_m"], p.y_m);
        self.float(&format!("{what}.heading_rad"), &py["heading_rad"], p.heading_rad);
    }

    pub fn ring(&mut self, py: &Value, r: &SonarRing) {
        let w = format!("sonar/ring {}", r.header.seq);
        self.header(&w, &py["header"], &r.header);
        self.floats(&format!("{w} range_m"), &py["range_m"], &r.range_m);
        self.floats(&format!("{w} bearing_rad"), &py["bearing_rad"], &r.bearing_rad);
        let stamps = py["reading_stamp_ns"].as_array().unwrap();
        assert_eq!(stamps.len(), r.reading_stamp_ns.len());
        for (i, (p, s)) in stamps.iter().zip(&r.reading_stamp_ns).enumerate() {
            self.int(&format!("{w} reading_stamp_ns[{i}]"), p, *s);
        }
        self.int(&format!("{w} valid_mask"), &py["valid_mask"], r.valid_mask.into());
        self.int(&format!("{w} panic_stop"), &py["panic_stop"], r.panic_stop.into());
    }

    pub fn odometry(&mut self, py: &Value, o: &Odometry) {
        let w = format!("odometry {}", o.header.seq);
        self.header(&w, &py["header"], &o.header);
        self.pose(&format!("{w} world_from_robot"), &py["world_from_robot"], &o.world_from_robot);
        self.float(&format!("{w} travelled_m"), &py["travelled_m"], o.travelled_m);
        self.float(&format!("{w} turned_rad"), &py["turned_rad"], o.turned_rad);
        let (pc, c) = (&py["command"], &o.command);
        self.header(&format!("{w} command.header"), &pc["header"], &c.header);
        self.int(&format!("{w} command.kind"), &pc["kind"], c.kind.into());
        self.int(&format!("{w} command.urgent"), &pc["urgent"], c.urgent.into());
        self.float(&format!("{w} command.distance_m"), &pc["distance_m"], c.distance_m);
        self.float(&format!("{w} command.angle_rad"), &pc["angle_rad"], c.angle_rad);
        self.float(&format!("{w} command.linear_mps"), &pc["linear_mps"], c.linear_mps);
        self.float(&format!("{w} command.angular_radps"), &pc["angular_radps"], c.angular_radps);
        self.int(&format!("{w} command.command_id"), &pc["command_id"], c.command_id.into());
        self.int(&format!("{w} command.reserved"), &pc["reserved"], c.reserved.into());
        self.int(&format!("{w} moving"), &py["moving"], o.moving.into());
        self.int(&format!("{w} command_accepted"), &py["command_accepted"], o.command_accepted.into());
    }
}
