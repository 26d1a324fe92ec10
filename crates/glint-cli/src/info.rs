//! `glint info`: what a scene holds and how good its BVHs are.

use crate::commands::SceneArgs;
use glint::world::ShapeRef;
use std::io::Write;

pub fn info_cmd(a: SceneArgs) -> Result<(), glint::Error> {
    let start = std::time::Instant::now();
    let mut session = a.open()?;
    let summary = session.description().summary.clone();
    let s = session.world()?;
    let load_s = start.elapsed().as_secs_f64();
    // A closed pipe (`glint info SCENE | head -1`) ends the listing quietly.
    let _ = print_info(&a, &s, &summary, load_s);
    Ok(())
}

fn print_info(a: &SceneArgs, s: &glint::world::World, summary: &[String], load_s: f64) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    let spheres = s.instances().iter().filter(|i| matches!(i.shape, ShapeRef::Sphere(_))).count();
    let curve_sets = s.curves().len();
    let mesh_instances = s.instances().len() - spheres - curve_sets;
    let unique_tris: usize = s.meshes().iter().map(|m| m.indices.len()).sum();
    writeln!(out, "scene            {}", a.scene.display())?;
    for line in summary {
        writeln!(out, "{line}")?;
    }
    writeln!(
        out,
        "shapes           {} ({} mesh instances, {} spheres, {} curve sets)",
        s.instances().len(),
        mesh_instances,
        spheres,
        curve_sets
    )?;
    writeln!(out, "meshes           {} unique, {} triangles stored", s.meshes().len(), unique_tris)?;
    writeln!(out, "triangles        {} (instanced)", s.triangle_count())?;
    writeln!(out, "lights           {}", s.lights().len())?;
    writeln!(out, "materials        {}", s.materials().len())?;
    writeln!(out, "camera           {}x{}", s.camera().width, s.camera().height)?;
    writeln!(out, "bvh split        {:?}", s.bvh_split())?;
    writeln!(out, "load time        {:.3} s (BVH builds {:.3} s)", load_s, s.bvh_build_seconds())?;
    let top = s.top_level().stats();
    writeln!(
        out,
        "top-level BVH    {} nodes, {} leaves, depth {}, leaf size {}..{} (mean {:.2}), SAH cost {:.2}, {} bytes",
        top.nodes, top.leaves, top.max_depth, top.min_leaf, top.max_leaf, top.mean_leaf, top.sah_cost, top.bytes
    )?;
    let mut total_bytes = top.bytes;
    let mut mesh_bytes = 0;
    for (i, m) in s.meshes().iter().enumerate() {
        let st = m.bvh.stats();
        total_bytes += st.bytes;
        mesh_bytes += m.memory_bytes();
        if i < 20 {
            writeln!(
                out,
                "mesh {:<4}        {} triangles: {} nodes, {} leaves, depth {}, leaf size {}..{} (mean {:.2}), SAH cost {:.2}, {} bytes",
                i, m.indices.len(), st.nodes, st.leaves, st.max_depth, st.min_leaf, st.max_leaf, st.mean_leaf, st.sah_cost, st.bytes
            )?;
        }
    }
    if s.meshes().len() > 20 {
        writeln!(out, "...              ({} more meshes)", s.meshes().len() - 20)?;
    }
    writeln!(out, "BVH memory       {} bytes ({:.2} MiB)", total_bytes, total_bytes as f64 / 1048576.0)?;
    writeln!(out, "mesh memory      {} bytes ({:.2} MiB)", mesh_bytes, mesh_bytes as f64 / 1048576.0)?;
    for (i, c) in s.curves().iter().enumerate() {
        let bytes = c.memory_bytes();
        writeln!(
            out,
            "curves {:<4}      {}: {} curves, {} segments, {} BVH primitives, {} bytes ({:.1} per segment, points and BVH included)",
            i,
            c.basis().plugin(),
            c.curve_count(),
            c.segment_count(),
            c.primitive_count(),
            bytes,
            bytes as f64 / c.segment_count().max(1) as f64
        )?;
    }
    Ok(())
}
