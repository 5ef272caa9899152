//! `envshadow scene NAME --obj OUT.obj --gltf OUT.glb [--without-ground]`: a built-in scene as
//! Wavefront OBJ or glTF 2.0 (its objects alone: a model to composite).

use std::path::Path;

pub(crate) fn run(name: &str, obj: Option<&Path>, gltf: Option<&Path>, without_ground: bool) -> Result<(), String> {
    let mut scene = scene::Scene::builtin(name).map_err(|e| e.to_string())?;
    if without_ground {
        scene.objects.retain(|o| o.name != "ground");
        if scene.objects.is_empty() {
            return Err(format!("{name}: nothing but its ground"));
        }
    }
    let summary = format!("{}: {} objects, {} triangles", scene.name, scene.objects.len(), scene.triangle_count());
    if let Some(obj) = obj {
        scene.write_obj(obj).map_err(|e| e.to_string())?;
        outln!("{summary} -> {}", obj.display());
    }
    if let Some(gltf) = gltf {
        scene.write_gltf(gltf).map_err(|e| e.to_string())?;
        outln!("{summary} -> {}", gltf.display());
    }
    Ok(())
}
