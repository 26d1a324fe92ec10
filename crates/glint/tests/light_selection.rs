//! Which light next-event estimation picks. By power, a weak light beside a strong one must
//! still be picked often enough: Veach's MIS scene (Mitsuba's `integrator_direct_*`
//! documentation scenes: spheres of power 200, 1, 1, 1, 1, each lighting its own highlight)
//! had 4x Mitsuba's error when the weak ones were picked 1 time in 204.

mod common;

use common::scratch::ScratchDir;
use glint::formats::ReadOptions;
use glint::lights::LightSelection;
use glint::session::Session;
use glint::world::World;

fn veach_lights_world(selection: LightSelection) -> std::sync::Arc<World> {
    let dir = ScratchDir::new(&format!("light-selection-{selection:?}"));
    let sphere = |x: f32, r: f32, radiance: f32| {
        format!(
            r#"<shape type="sphere"><point name="center" x="{x}" y="0" z="0"/><float name="radius" value="{r}"/>
               <emitter type="area"><rgb name="radiance" value="{radiance}"/></emitter></shape>"#
        )
    };
    // Radiance x area: 800 * 0.25 * 4 pi = 200 * 4 pi, the others 1 * 4 pi.
    let lights = [sphere(10.0, 0.5, 800.0), sphere(-1.25, 0.1, 100.0), sphere(1.25, 0.3, 100.0 / 9.0)].join("\n")
        + &sphere(3.75, 0.9, 1.0 / 0.81)
        + &sphere(-3.75, 0.05, 400.0);
    let scene = format!(
        r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/>
           <integer name="height" value="4"/></film></sensor>{lights}</scene>"#
    );
    let path = dir.join("lights.xml");
    std::fs::write(&path, scene).unwrap();
    let mut session = Session::open(&path, &ReadOptions::default()).unwrap();
    session.edit().light_selection = selection;
    session.world().unwrap()
}

#[test]
fn by_power_no_light_is_picked_less_than_half_as_often_as_uniformly() {
    let world = veach_lights_world(LightSelection::Power);
    let n = 5;
    let pmfs: Vec<f32> = (0..n).map(|i| world.light_pmf(i)).collect();
    let sum: f32 = pmfs.iter().sum();
    assert!((sum - 1.0).abs() < 1e-5, "pmfs {pmfs:?} sum to {sum}");
    for &p in &pmfs {
        assert!(p >= 0.5 / n as f32 * (1.0 - 1e-5), "a light is picked with probability {p}: {pmfs:?}");
    }
    // Power still counts: the strong light is picked most (by power alone 200/204).
    let strongest = pmfs.iter().cloned().fold(0.0, f32::max);
    assert_eq!(strongest, pmfs[0], "{pmfs:?}");
    assert!(pmfs[0] > 0.5, "{pmfs:?}");
}

#[test]
fn uniform_selection_picks_every_light_alike() {
    let world = veach_lights_world(LightSelection::Uniform);
    for i in 0..5 {
        assert!((world.light_pmf(i) - 0.2).abs() < 1e-6);
    }
}
