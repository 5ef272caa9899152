// A wedge footprint built on the GPU (build.wgsl writes it, wedge.wgsl's vs_polygon draws it):
// a convex polygon in NDC of `count` corners over `edges` silhouette edges from `first`.

const FOOTPRINT_CORNERS: u32 = 20u;

struct Footprint {
    count: u32,
    first: u32,
    edges: u32,
    pad: u32,
    corners: array<vec2<f32>, 20>,
}
