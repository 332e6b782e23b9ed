//! The stereo visual odometry's settings (003): the `[odometry]` table of a file
//! (`--odometry`, shipped as `missions/odometry/003.toml`), every number checked against its
//! range with the file, line and key named, and turned into the kernel's parameters for a
//! frame size and the world's camera.

use std::path::Path;

use harvey_config::range::{OutOfRange, Range, check, check_int};
use harvey_config::spans::KeyPath;
use harvey_vision::moravec::MoravecParams;
use harvey_vision::odometry::{LucasParams, OdometryParams, Rig, Solver, Tolerance};
use harvey_vision::stereo::StereoParams;
use serde::Deserialize;

/// The `[odometry]` table. Every field is required: the file says where each number comes from.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometryConfig {
    pub band_rows: u32,
    pub near_m: f64,
    pub far_m: f64,
    pub patch: u32,
    pub min_score: f64,
    pub min_margin: f64,
    pub interest_window: u32,
    pub interest_threshold: u32,
    pub suppress_radius: u32,
    pub max_corners: u32,
    pub track_min_score: f64,
    pub box_sigmas: f64,
    pub rigidity_sigmas: f64,
    pub rigidity_floor_m: f64,
    pub edit_chi2: f64,
    pub plausible_chi2: f64,
    pub min_features: u32,
    pub spacing_px: f64,
    pub min_turn: f64,
    pub disparity_sd_px: f64,
    pub position_sd_px: f64,
    /// The prediction's standard deviation when a request gives none: a share of the distance
    /// travelled plus a floor; the heading's a floor, a share of the turn and so much per metre.
    pub prior_sd_per_m: f64,
    pub prior_sd_floor_m: f64,
    pub prior_heading_sd_deg: f64,
    pub prior_heading_sd_per_deg: f64,
    pub prior_heading_sd_deg_per_m: f64,
    /// Points between these heights (m above the floor) are obstacles.
    pub obstacle_min_z_m: f64,
    pub obstacle_max_z_m: f64,
    pub lucas: LucasConfig,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LucasConfig {
    pub levels: u32,
    pub radius: u32,
    pub iterations: u32,
    pub huber: f64,
}

#[derive(Deserialize)]
struct File {
    odometry: Option<OdometryConfig>,
}

/// A file the settings cannot be read from, naming it (and the line and key where there is one).
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{file}: {message}")]
    Read { file: String, message: String },
    #[error("{file}: no [odometry] table")]
    NoTable { file: String },
    #[error("{file}:{line}: key `{key}`: {detail}")]
    OutOfRange { file: String, line: usize, key: String, detail: String },
}

impl OdometryConfig {
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| ConfigError::Read { file: file.clone(), message: e.to_string() })?;
        Self::parse(&text, &file)
    }

    /// The `[odometry]` table of `text` (the file `file`); other tables are ignored.
    pub fn parse(text: &str, file: &str) -> Result<Self, ConfigError> {
        let read = |message: String| ConfigError::Read { file: file.to_owned(), message };
        let doc: toml::Table = toml::from_str(text).map_err(|e| read(e.message().to_owned()))?;
        let only: toml::Table = doc.into_iter().filter(|(k, _)| k == "odometry").collect();
        let parsed: File = serde_path_to_error::deserialize(only)
            .map_err(|e| read(format!("key `{}`: {}", e.path(), e.inner().message())))?;
        let c = parsed.odometry.ok_or_else(|| ConfigError::NoTable { file: file.to_owned() })?;
        c.check().map_err(|why| ConfigError::OutOfRange {
            file: file.to_owned(),
            line: harvey_config::line_of_key(text, &why.key),
            key: why.key.to_string(),
            detail: why.detail,
        })?;
        Ok(c)
    }

    fn check(&self) -> Result<(), OutOfRange> {
        let k = KeyPath::default().key("odometry");
        let unit = Range::closed(0.0, 1.0, "");
        check_int(&k.key("band_rows"), self.band_rows, 0, 64, "rows")?;
        check(&k.key("near_m"), self.near_m, &Range::above(0.0, 100.0, "m"))?;
        check(&k.key("far_m"), self.far_m, &Range::above(self.near_m, 1e6, "m"))?;
        check_int(&k.key("patch"), self.patch, 3, 63, "px")?;
        if self.patch.is_multiple_of(2) {
            let detail = format!("{} is even; a patch has a centre pixel", self.patch);
            return Err(OutOfRange { key: k.key("patch"), detail });
        }
        check(&k.key("min_score"), self.min_score, &unit)?;
        check(&k.key("min_margin"), self.min_margin, &unit)?;
        check_int(&k.key("interest_window"), self.interest_window, 3, 31, "px")?;
        check_int(&k.key("interest_threshold"), self.interest_threshold, 0, 1 << 24, "")?;
        check_int(&k.key("suppress_radius"), self.suppress_radius, 0, 64, "px")?;
        check_int(&k.key("max_corners"), self.max_corners, 1, 2000, "")?;
        check(&k.key("track_min_score"), self.track_min_score, &unit)?;
        check(&k.key("box_sigmas"), self.box_sigmas, &Range::above(0.0, 10.0, "sd"))?;
        check(&k.key("rigidity_sigmas"), self.rigidity_sigmas, &Range::above(0.0, 20.0, "sd"))?;
        check(&k.key("rigidity_floor_m"), self.rigidity_floor_m, &Range::closed(0.0, 1.0, "m"))?;
        check(&k.key("edit_chi2"), self.edit_chi2, &Range::above(0.0, 1000.0, ""))?;
        check(&k.key("plausible_chi2"), self.plausible_chi2, &Range::above(0.0, 1e6, ""))?;
        check_int(&k.key("min_features"), self.min_features, 3, 1000, "")?;
        check(&k.key("spacing_px"), self.spacing_px, &Range::closed(0.0, 100.0, "px"))?;
        check(&k.key("min_turn"), self.min_turn, &unit)?;
        check(&k.key("disparity_sd_px"), self.disparity_sd_px, &Range::above(0.0, 10.0, "px"))?;
        check(&k.key("position_sd_px"), self.position_sd_px, &Range::above(0.0, 10.0, "px"))?;
        check(&k.key("prior_sd_per_m"), self.prior_sd_per_m, &Range::closed(0.0, 1.0, ""))?;
        check(&k.key("prior_sd_floor_m"), self.prior_sd_floor_m, &Range::above(0.0, 1.0, "m"))?;
        check(&k.key("prior_heading_sd_deg"), self.prior_heading_sd_deg, &Range::above(0.0, 45.0, "deg"))?;
        check(&k.key("prior_heading_sd_per_deg"), self.prior_heading_sd_per_deg, &unit)?;
        let per_m = Range::closed(0.0, 90.0, "deg/m");
        check(&k.key("prior_heading_sd_deg_per_m"), self.prior_heading_sd_deg_per_m, &per_m)?;
        check(&k.key("obstacle_min_z_m"), self.obstacle_min_z_m, &Range::closed(0.0, 10.0, "m"))?;
        let above_min = Range::above(self.obstacle_min_z_m, 10.0, "m");
        check(&k.key("obstacle_max_z_m"), self.obstacle_max_z_m, &above_min)?;
        let l = k.key("lucas");
        check_int(&l.key("levels"), self.lucas.levels, 1, 8, "")?;
        check_int(&l.key("radius"), self.lucas.radius, 1, 16, "px")?;
        check_int(&l.key("iterations"), self.lucas.iterations, 1, 50, "")?;
        check(&l.key("huber"), self.lucas.huber, &Range::above(0.0, 100.0, "sd"))
    }

    /// The kernel's parameters for `width x height` views of a camera of focal length
    /// `focal_px`, `height_m` up, the pair `baseline_m` apart.
    pub fn params(
        &self,
        focal_px: f64,
        size: [u32; 2],
        height_m: f64,
        baseline_m: f64,
        lucas: bool,
    ) -> OdometryParams {
        let rig = Rig {
            focal_px,
            centre_px: [f64::from(size[0]) / 2.0, f64::from(size[1]) / 2.0],
            baseline_m,
            height_m,
            disparity_sd_px: self.disparity_sd_px,
            position_sd_px: self.position_sd_px,
        };
        let l = self.lucas;
        let registration = LucasParams {
            levels: l.levels as usize,
            radius: l.radius as usize,
            iterations: l.iterations as usize,
            huber: l.huber,
        };
        OdometryParams {
            rig,
            stereo: StereoParams {
                focal_px: focal_px as f32,
                baseline_m: baseline_m as f32,
                band_rows: self.band_rows as usize,
                near_m: self.near_m as f32,
                far_m: self.far_m as f32,
                patch: self.patch as usize,
                min_score: self.min_score as f32,
                min_margin: self.min_margin as f32,
                moravec: MoravecParams {
                    window: self.interest_window as usize,
                    threshold: self.interest_threshold,
                    suppress_radius: self.suppress_radius as usize,
                    max_corners: self.max_corners as usize,
                },
            },
            track_min_score: self.track_min_score as f32,
            box_sigmas: self.box_sigmas,
            rigidity: Tolerance { sigmas: self.rigidity_sigmas, floor_m: self.rigidity_floor_m },
            edit_chi2: self.edit_chi2,
            plausible_chi2: self.plausible_chi2,
            min_features: self.min_features as usize,
            spacing_px: self.spacing_px as f32,
            min_turn: self.min_turn,
            solver: if lucas { Solver::Lucas(registration) } else { Solver::MatchThenSolve },
        }
    }
}
