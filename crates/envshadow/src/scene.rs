//! `envshadow scene NAME --obj OUT.obj`: a built-in scene's geometry as Wavefront OBJ.

use std::path::Path;

pub(crate) fn run(name: &str, obj: &Path) -> Result<(), String> {
    let scene = scene::Scene::builtin(name).map_err(|e| e.to_string())?;
    scene.write_obj(obj).map_err(|e| e.to_string())?;
    outln!(
        "{}: {} objects, {} triangles -> {}",
        scene.name,
        scene.objects.len(),
        scene.triangle_count(),
        obj.display()
    );
    Ok(())
}
