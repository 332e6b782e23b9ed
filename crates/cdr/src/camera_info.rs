//! ROS 2's `sensor_msgs/msg/CameraInfo`, as Jazzy defines it: the pinhole calibration that lets
//! Foxglove's 3D panel place the camera's image in the scene and its Image panel draw 3D markers
//! over it.

use crate::codec::{Cdr, CdrError, CdrReader, CdrWriter};
use crate::geometry::read_std_header;
use crate::schema::Def;
use crate::types::{Ros2Msg, STD_HEADER, write_std_header};

static REGION_OF_INTEREST: Def = Def {
    name: "sensor_msgs/RegionOfInterest",
    text: "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n",
    deps: &[],
};
static CAMERA_INFO: Def = Def {
    name: "sensor_msgs/CameraInfo",
    text: "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\n\
           float64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\n\
           sensor_msgs/RegionOfInterest roi\n",
    deps: &[&STD_HEADER, &REGION_OF_INTEREST],
};

/// An undistorted pinhole camera (`plumb_bob` with zero coefficients) of focal length `focal_px`
/// and principal point `centre_px`, in ROS's pixel convention (pixel `(u, v)`'s centre at `u, v`).
#[derive(Debug, Clone, PartialEq)]
pub struct CameraInfo {
    pub stamp_ns: u64,
    pub frame_id: String,
    pub width_px: u32,
    pub height_px: u32,
    pub focal_px: f64,
    pub centre_px: [f64; 2],
}

impl Cdr for CameraInfo {
    fn write(&self, w: &mut CdrWriter) {
        write_std_header(self.stamp_ns, &self.frame_id, w);
        [self.height_px, self.width_px].write(w);
        w.string("plumb_bob");
        w.prim(5u32);
        [0.0f64; 5].write(w);
        let (f, [cx, cy]) = (self.focal_px, self.centre_px);
        [f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0].write(w);
        [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0f64].write(w);
        [f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0f64].write(w);
        [0u32; 2].write(w); // binning
        [0u32; 4].write(w); // roi: the whole image
        w.prim(0u8);
    }

    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let (stamp_ns, frame_id) = read_std_header(r)?;
        let [height_px, width_px] = <[u32; 2]>::read(r)?;
        let at = r.offset();
        let model = r.string()?;
        let n = r.prim::<u32>()? as usize;
        let d = (0..n.min(r.remaining() / 8 + 1)).map(|_| r.prim::<f64>()).collect::<Result<Vec<_>, _>>()?;
        if model != "plumb_bob" || d.len() != n || d.iter().any(|&c| c != 0.0) {
            return Err(CdrError::Invalid { at, what: format!("a {model} camera with distortion {d:?}") });
        }
        let k = <[f64; 9]>::read(r)?;
        let _r = <[f64; 9]>::read(r)?;
        let _p = <[f64; 12]>::read(r)?;
        let _binning_roi = (<[u32; 6]>::read(r)?, r.prim::<u8>()?);
        Ok(Self { stamp_ns, frame_id, width_px, height_px, focal_px: k[0], centre_px: [k[2], k[5]] })
    }
}

impl Ros2Msg for CameraInfo {
    const DEF: &'static Def = &CAMERA_INFO;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Schema, decode, encode, full_text};

    #[test]
    fn camera_info_round_trips_and_decodes_by_its_schema() {
        let info = CameraInfo {
            stamp_ns: 100,
            frame_id: "camera".into(),
            width_px: 640,
            height_px: 480,
            focal_px: 500.0,
            centre_px: [319.5, 239.5],
        };
        let bytes = encode(&info, Vec::new());
        assert_eq!(decode::<CameraInfo>(&bytes).expect("decodes"), info);
        let v = Schema::parse(CAMERA_INFO.name, &full_text(&CAMERA_INFO)).expect("schema").decode(&bytes);
        let v = v.expect("decodes by schema");
        assert_eq!(v["k"][0], 500.0);
        assert_eq!(v["p"][6], 239.5);
        assert_eq!(v["roi"]["do_rectify"], false);
        assert_eq!(v["d"].as_array().map(Vec::len), Some(5));
    }
}
