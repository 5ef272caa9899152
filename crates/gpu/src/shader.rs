//! WGSL sources and their composition. Shaders live in `crates/<crate>/shaders/`; a file may start with
//! `// requires: <crate>/<file>.wgsl ...` lines naming library files (functions only) that are
//! prepended, in order, before it is compiled. The workspace test that validates every shader
//! with naga resolves the same lines.

/// Library WGSL of this crate, by the name used in `// requires:` lines.
pub const LIBRARY: &[(&str, &str)] = &[
    ("gpu/brdf.wgsl", include_str!("../shaders/brdf.wgsl")),
    ("gpu/sh9.wgsl", include_str!("../shaders/sh9.wgsl")),
    ("gpu/fullscreen.wgsl", include_str!("../shaders/fullscreen.wgsl")),
];

/// The names listed on `// requires:` lines at the top of `source`.
#[must_use]
pub fn requires(source: &str) -> Vec<&str> {
    source
        .lines()
        .filter(|l| !l.trim_start().starts_with("enable "))
        .map_while(|l| l.trim().strip_prefix("//").map(str::trim))
        .filter_map(|l| l.strip_prefix("requires:"))
        .flat_map(str::split_whitespace)
        .collect()
}

/// `source` with its required library files prepended. `extra` adds a crate's own library
/// files to this crate's [`LIBRARY`]. Panics name a missing file: the table is static, so a
/// test catches it.
#[must_use]
pub fn compose(source: &str, extra: &[(&str, &str)]) -> String {
    let registered = |name: &str| {
        LIBRARY
            .iter()
            .chain(extra)
            .find(|(n, _)| *n == name)
            .map(|(_, text)| (*text).to_string())
            .ok_or(name.to_string())
    };
    compose_with(source, registered).unwrap_or_else(|name| panic!("shader library file {name} is not registered"))
}

/// `source` with the library files its `// requires:` lines name prepended, each fetched by
/// `resolve` (from a table at run time, from `crates/<crate>/shaders/` in the workspace test); `enable`
/// directives stay first.
///
/// # Errors
/// The first error `resolve` returns.
pub fn compose_with<E>(source: &str, resolve: impl Fn(&str) -> Result<String, E>) -> Result<String, E> {
    let (enables, body): (Vec<&str>, Vec<&str>) = source.lines().partition(|l| l.trim_start().starts_with("enable "));
    let mut text = enables.join("\n");
    text.push('\n');
    for name in requires(source) {
        text.push_str(&resolve(name)?);
        text.push('\n');
    }
    text.push_str(&body.join("\n"));
    Ok(text)
}

/// Compiles `source` (composed with [`compose`]) into a module.
#[must_use]
pub fn module(device: &wgpu::Device, label: &str, source: &str, extra: &[(&str, &str)]) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(compose(source, extra).into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requires_lines_are_read_and_enables_stay_first() {
        let src = "enable clip_distances;\n// requires: gpu/sh9.wgsl\nfn f() {}";
        assert_eq!(requires(src), vec!["gpu/sh9.wgsl"]);
        let text = compose(src, &[]);
        assert!(text.starts_with("enable clip_distances;"));
        assert!(text.contains("fn sh9_irradiance") && text.ends_with("fn f() {}"));
    }
}
