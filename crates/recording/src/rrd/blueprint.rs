//! The viewer layout a Harvey recording opens with: the camera with the Expecter's windows (a
//! stereo pair's right image in a tab beside it), the log (one entity per source, so the source
//! shows in its column) and the state lanes (mission step, servoing level, acceptor state, UMS
//! localised or lost) down the left; the world view framed on the action (a tab for the whole
//! world) and one plot per quantity, each titled with its unit, down the right.

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintPanel, Grid, Horizontal, SelectionPanel, Spatial2DView, StateTimelineView, Tabs,
    TextLogView, TimePanel, TimeSeriesView, Vertical,
};

/// One plot panel: its title (short, with the unit, to fit a quarter of the column; the series'
/// names say the rest) and the entity subtree it shows.
pub const PLOTS: [(&str, &str); 8] = [
    ("uncertainty (m²)", "/plots/uncertainty"),
    ("wedge (deg)", "/plots/heading"),
    ("deviation (m)", "/plots/deviation"),
    ("servo turn (deg)", "/plots/servo"),
    ("speed (m/s)", "/plots/speed"),
    ("turn rate (deg/s)", "/plots/turning"),
    ("light (px)", "/plots/vision"),
    ("latency (ms)", "/plots/latency"),
];

/// Harvey's layout, with the side panels folded so the views get the window.
pub fn harvey() -> Blueprint {
    let plots = PLOTS.iter().map(|(title, origin)| TimeSeriesView::new(*title).with_origin(*origin).into());
    let world = Tabs::new([
        Spatial2DView::new("world around the robot (top-down, y up)")
            .with_origin("/world")
            .with_contents(["+ /world/**", "- /world/map/**"])
            .into(),
        Spatial2DView::new("whole world (top-down, y up)")
            .with_origin("/world")
            .with_contents(["+ /world/**", "- /world/near/**"])
            .into(),
    ]);
    // A stereo pair's right image in a tab of its own (the overlays are the left image's).
    let camera = Tabs::new([
        Spatial2DView::new("camera")
            .with_origin("/camera")
            .with_contents(["+ /camera/**", "- /camera/right/**"])
            .into(),
        Spatial2DView::new("right camera (stereo)").with_origin("/camera/right").into(),
    ]);
    let left = Vertical::new([
        camera.into(),
        TextLogView::new("log").with_origin("/log").into(),
        StateTimelineView::new("mission, servoing, acceptor, UMS").with_origin("/states").into(),
    ])
    .with_row_shares([0.5, 0.32, 0.18]);
    let right = Vertical::new([world.into(), Grid::new(plots).with_grid_columns(4).into()])
        .with_row_shares([0.6, 0.4]);
    Blueprint::new(Horizontal::new([left.into(), right.into()]).with_column_shares([0.44, 0.56]))
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(TimePanel::new().with_timeline("sim_time").with_state(PanelState::Collapsed))
}
