//! `envshadow scene NAME --obj OUT.obj --gltf OUT.glb`: a built-in scene as Wavefront OBJ or
//! glTF 2.0.

use std::path::Path;

pub(crate) fn run(name: &str, obj: Option<&Path>, gltf: Option<&Path>) -> Result<(), String> {
    let scene = scene::Scene::builtin(name).map_err(|e| e.to_string())?;
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
