//! glint agrees with Mitsuba 3 on the validation scenes in tests/scenes/mitsuba/: for each
//! scene, rendered at the sample count the references were made for,
//! (a) every channel's image mean is within 1% of Mitsuba's high-spp reference, and
//! (b) the relative MSE against that reference is at most 1.3 times the relative MSE of
//!     Mitsuba's own renders at the same sample count (recorded by make-references).
//! Regenerate the references with tests/scenes/mitsuba/make-references.

use glint::io::{read_image, Image};
use glint::render::{render, Silent};
mod common;

use common::load::load;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/mitsuba")
}

/// mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01), as in make-references.
fn rel_mse(x: &Image, reference: &Image) -> f64 {
    let mut s = 0.0f64;
    for (a, b) in x.pixels.iter().zip(&reference.pixels) {
        for k in 0..3 {
            let (a, b) = (a.channel(k) as f64, b.channel(k) as f64);
            s += (a - b) * (a - b) / (b * b + 1e-2);
        }
    }
    s / (3 * x.pixels.len()) as f64
}

/// The scene's entry in references/references.json.
fn reference_entry(name: &str) -> serde_json::Value {
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("references/references.json")).unwrap()).unwrap();
    index[name].clone()
}

fn render_at(name: &str, spp: u64) -> Image {
    let spp_text = spp.to_string();
    let scene = load(&dir().join(format!("{name}.xml")), &[("spp", &spp_text)], None).unwrap();
    assert_eq!(scene.settings.spp as u64, spp);
    render(&scene.world, &scene.integrator, &scene.settings, &Silent).image
}

/// As `check`, with the light selection set to `selection` (the session's override, as the
/// command line's `--light-selection` sets it).
fn check_with_selection(name: &str, selection: glint::lights::LightSelection) -> f64 {
    use glint::formats::ReadOptions;
    use glint::session::Session;
    let entry = reference_entry(name);
    let mitsuba_rel_mse = entry["mitsuba_rel_mse"].as_f64().unwrap();
    let mut session = Session::open(&dir().join(format!("{name}.xml")), &ReadOptions::default()).unwrap();
    session.edit().light_selection = selection;
    let world = session.world().unwrap();
    let mut settings = session.render_settings();
    settings.spp = entry["test_spp"].as_u64().unwrap() as u32;
    let image = render(&world, &session.integrator(), &settings, &Silent).image;
    let reference = read_image(&dir().join(format!("references/{name}.exr"))).unwrap();
    let (ours, theirs) = (image.channel_means(), reference.channel_means());
    let err = rel_mse(&image, &reference);
    eprintln!(
        "{name} ({selection:?}): means {ours:?} vs {theirs:?}; relMSE {err:.3e} vs Mitsuba's {mitsuba_rel_mse:.3e}"
    );
    assert_means_agree(name, ours, theirs, 0.01);
    err / mitsuba_rel_mse
}

/// Criterion (a): every channel mean within `tolerance` (relative) of Mitsuba's.
fn assert_means_agree(name: &str, ours: [f64; 3], theirs: [f64; 3], tolerance: f64) {
    for k in 0..3 {
        let rel = (ours[k] - theirs[k]).abs() / theirs[k].max(1e-6);
        assert!(
            rel < tolerance,
            "{name}: channel {k} mean {} differs from Mitsuba's {} by {:.2}%",
            ours[k],
            theirs[k],
            rel * 100.0
        );
    }
}

/// Criteria (a), means within 1%, and (b).
fn check(name: &str) {
    check_with_mean_tolerance(name, 0.01);
}

fn check_with_mean_tolerance(name: &str, tolerance: f64) {
    check_against(name, tolerance, 1.3);
}

/// Criterion (a) with `tolerance`, and (b) with the relative MSE at most `error_ratio` times
/// Mitsuba's.
fn check_against(name: &str, tolerance: f64, error_ratio: f64) {
    let entry = reference_entry(name);
    let mitsuba_rel_mse = entry["mitsuba_rel_mse"].as_f64().unwrap();
    let image = render_at(name, entry["test_spp"].as_u64().unwrap());
    let reference = read_image(&dir().join(format!("references/{name}.exr"))).unwrap();
    assert_eq!((image.width, image.height), (reference.width, reference.height));
    let (ours, theirs) = (image.channel_means(), reference.channel_means());
    let err = rel_mse(&image, &reference);
    eprintln!("{name}: means {ours:?} vs {theirs:?}; relMSE {err:.3e} vs Mitsuba's {mitsuba_rel_mse:.3e}");
    assert_means_agree(name, ours, theirs, tolerance);
    assert!(
        err <= error_ratio * mitsuba_rel_mse,
        "{name}: relative MSE {err:.3e} > {error_ratio} x Mitsuba's {mitsuba_rel_mse:.3e}"
    );
}

#[test]
fn cornell_box() {
    check("cornell-box");
}

#[test]
fn glass_and_mirror_spheres() {
    check("spheres");
}

#[test]
fn rough_conductors_under_an_environment_map() {
    check("roughmetal");
}

#[test]
fn textures_and_plastics() {
    check("textures");
}

#[test]
fn point_and_spot_lights() {
    check("lights");
}

#[test]
fn thin_lens_and_glass() {
    check("thinlens");
}

#[test]
fn spherical_area_lights() {
    check("sphere-light");
}

/// Mitsuba's `direct` with 2 emitter and 3 BSDF samples per shading point.
#[test]
fn direct_integrator_with_both_strategies() {
    check("direct-mis");
}

/// `direct` with BSDF samples only: no light sampling, so its error is that of BSDF sampling.
#[test]
fn direct_integrator_with_bsdf_samples_only() {
    check("direct-bsdf");
}

#[test]
fn direct_integrator_with_emitter_samples_only() {
    check("direct-emitter");
}

/// Mitsuba's own `mitsuba.cornell_box()`, written out as XML, with its gaussian filter: glint
/// splats samples as Mitsuba does, so the per-pixel noise is comparable as well as the means.
#[test]
fn mitsubas_own_cornell_box() {
    check("cornell-box-mitsuba");
}

/// Wavelength:value spectra (reflectances, conductor eta and k, an area light), a scene-level
/// sampler and a `<path>` (the texture is found through it).
#[test]
fn sampled_spectra_sampler_and_path() {
    check("spectra");
}

/// A blackbody light and a constant-spectrum sky over flat reflectances, against Mitsuba's
/// scalar_spectral render (the one variant that renders blackbodies).
#[test]
fn blackbody_against_a_spectral_render() {
    check("blackbody");
}

/// Mitsuba's serialized meshes: shape_index, stored normals and uvs, face_normals.
#[test]
fn serialized_meshes() {
    check("serialized");
}

/// The disk's polar uv mapping, as Mitsuba's.
#[test]
fn disk_polar_uv() {
    check("disk");
}

/// Named conductor presets beyond the common metals (`a-C`, `TiN`, `W`, `Cu2O_palik`), smooth
/// and rough: the RGB values are Mitsuba's own, so the spheres must match.
#[test]
fn conductor_presets() {
    check("conductor-presets");
}

/// Tangent-space normal maps on a rectangle, a sphere and a cube (Mitsuba's dp/du frames).
#[test]
fn normal_maps() {
    check("normalmap");
}

/// Bump maps: the exact gradient of a bilinearly filtered height bitmap.
#[test]
fn bump_maps() {
    check("bumpmap");
}

/// Opacity masks seen by the camera and in shadows (a texture and a constant).
#[test]
fn opacity_masks() {
    check("mask");
}

/// Per-vertex and per-face PLY attributes as textures.
#[test]
fn mesh_attributes() {
    check("mesh-attribute");
}

/// As `check`, for scenes with participating media: channel means within 2%.
fn check_media(name: &str) {
    check_with_mean_tolerance(name, 0.02);
}

#[test]
fn volpath_fog_in_a_null_sphere() {
    check_media("medium-fog");
}

#[test]
fn volpath_scattering_medium_in_glass() {
    check_media("medium-glass");
}

#[test]
fn volpath_camera_in_fog_with_rgb_extinction() {
    check_media("medium-rgb");
}

/// Albedo from gridvolumes: trilinear/repeat RGB grid rotated by its to_world inside glass
/// without emitter sampling, and a nearest/mirror grey grid in a null-bounded cube.
#[test]
fn volpath_albedo_from_grid_volumes() {
    check_media("medium-albedo-grid");
}

/// A heterogeneous medium: density from a gridvolume whose box is smaller than the null
/// cube around it (delta tracking for distances, ratio tracking for shadow rays).
#[test]
fn volpath_heterogeneous_medium_from_a_density_grid() {
    check_media("medium-heterogeneous");
}

/// The cylinder: p0/p1/radius and to_world, Mitsuba's uv, one- and two-sided, flip_normals.
#[test]
fn cylinder_shape() {
    check("cylinder");
}

/// sdfgrid: a torus grid placed directly with smooth normals and through a rotating
/// shapegroup/instance with analytic normals.
#[test]
fn sdfgrid_shape() {
    check("sdfgrid");
}

/// shapegroup and instance: a group of a serialized mesh, a sphere and a cube drawn three
/// times through the instances' transforms.
#[test]
fn shapegroup_instances() {
    check("instance");
}

/// The orthographic sensor: a scaled to_world, a film that is not square, near and far clip.
#[test]
fn orthographic_sensor() {
    check("orthographic");
}

/// A film crop window: the output is the window, with the full render's pixels there.
#[test]
fn film_crop_window() {
    check("crop");
}

/// Lights that project a texture: a projector and a textured spot.
#[test]
fn projector_and_textured_spot() {
    check("projector");
}

#[test]
fn principled_bsdf_under_an_environment_map() {
    check("principled");
}

/// Mitsuba's `principledthin`: specular and diffuse transmission through thin spheres and a
/// sheet, sheen, anisotropy, flatness, textured base_color, roughness and eta.
#[test]
fn principled_thin_bsdf_under_an_environment_map() {
    check("principledthin");
}

#[test]
fn blended_bsdfs_and_twosided_around_and_inside_a_blend() {
    check("blend");
}

/// Anisotropic GGX and Beckmann conductors on spheres and a rectangle (alpha_u along dp/du,
/// as Mitsuba orients it), roughness from checkerboard textures on a conductor and a glass.
#[test]
fn anisotropic_and_textured_roughness() {
    check("anisotropic");
}

/// Nonlinear smooth and rough plastics, an anisotropic pplastic and a polarizer sheet, as
/// Mitsuba's RGB variants render them.
#[test]
fn nonlinear_plastics_pplastic_and_polarizer() {
    check("plastics");
}

/// Area emitters whose radiance is a texture (a bitmap on a rectangle and on a cylinder, a
/// checkerboard on a sphere), read at the surface's uv, and an emitting cylinder.
#[test]
fn textured_area_emitters_and_an_emitting_cylinder() {
    check("area-textured");
}

/// A rectangle light with a high-contrast HDR bitmap, an orthographic camera, a blend BSDF and
/// a cylinder. glint samples the light by its bilinearly filtered texels (Mitsuba by its
/// texels, piecewise constant), so its error must be no larger than Mitsuba's (issue 30's
/// target: at most 1.0x; it was 1.83x when the light was sampled by area).
#[test]
fn rectangle_light_with_an_hdr_bitmap() {
    check_against("area-hdr-panel", 0.01, 1.0);
}

/// 400 sphere lights of radiance spanning 100x, rendered with the light tree: means within 1%
/// and relative MSE at most 1.3x Mitsuba's (which picks lights uniformly); power selection,
/// the default, is held to the same.
#[test]
fn many_sphere_lights_by_the_tree_and_by_power() {
    use glint::lights::LightSelection;
    for selection in [LightSelection::Tree, LightSelection::Power] {
        let ratio = check_with_selection("many-spheres", selection);
        assert!(ratio <= 1.3, "many-spheres ({selection:?}): relative MSE {ratio:.2}x Mitsuba's");
    }
}

/// A large light whose bitmap is a few bright texels on a dim ground (46.8x Mitsuba's error
/// when sampled by area), at most 1.0x Mitsuba's error.
#[test]
fn large_light_of_a_few_bright_texels() {
    check_against("area-bright-texels", 0.01, 1.0);
}

/// A disk light whose bitmap is a few bright texels on a dim ground, read at the disk's polar
/// uv: sampled by its texels times the disk's area Jacobian and mapped onto the disk (glint's
/// disk is a fan of triangles; Mitsuba's is exact), at most 1.0x Mitsuba's error.
#[test]
fn disk_light_of_a_few_bright_texels() {
    check_against("area-textured-disk", 0.01, 1.0);
}

/// Curves and the hair BSDF: a fur ball of B-spline curves with pigmented hair and the same
/// curves, smaller, as linear curves with an absorption coefficient and rough scales, under
/// an environment map and a sphere light.
#[test]
fn hair_on_curves() {
    check("hair");
}
