//! What decides how an image looks: the camera, the views, the clipping plane, the
//! surface's colours and normals, and the shading mode.

/// Orthographic or perspective projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Parallel rays: sizes do not shrink with distance.
    Orthographic,
    /// Rays from an eye point, with the given vertical field of view in degrees.
    Perspective {
        /// The vertical field of view, degrees.
        fov_deg: f64,
    },
}

/// The named views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum View {
    /// From the front-right-top, azimuth −45°, elevation 35.26° (isometric).
    Iso,
    /// From the front (−y), looking north.
    Front,
    /// From above, looking down, north up.
    Top,
    /// From the east (+x), looking west.
    Side,
}

impl View {
    /// Every named view, in contact-sheet order.
    pub const ALL: [View; 4] = [View::Iso, View::Front, View::Top, View::Side];

    /// The view's azimuth and elevation in degrees.
    #[must_use]
    pub fn angles(self) -> (f64, f64) {
        match self {
            View::Iso => (-45.0, 35.264_389_682_754_654),
            View::Front => (-90.0, 0.0),
            View::Top => (-90.0, 90.0),
            View::Side => (0.0, 0.0),
        }
    }

    /// Parses `iso`, `front`, `top` or `side`.
    #[must_use]
    pub fn parse(s: &str) -> Option<View> {
        match s {
            "iso" => Some(View::Iso),
            "front" => Some(View::Front),
            "top" => Some(View::Top),
            "side" => Some(View::Side),
            _ => None,
        }
    }
}

/// Where the camera looks from. The target is the centre of the solid's bounding box;
/// the camera sits in the direction given by azimuth (degrees from +x towards +y) and
/// elevation (degrees above the xy plane), far enough to frame the whole solid, and
/// `zoom` magnifies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Degrees from +x towards +y of the direction to the camera.
    pub azimuth_deg: f64,
    /// Degrees above the horizontal of the direction to the camera.
    pub elevation_deg: f64,
    /// Magnification (1 frames the bounding sphere).
    pub zoom: f64,
    /// The projection.
    pub projection: Projection,
}

impl Camera {
    /// An orthographic camera for a named view, zoom 1.
    #[must_use]
    pub fn view(view: View) -> Self {
        let (azimuth_deg, elevation_deg) = view.angles();
        Self {
            azimuth_deg,
            elevation_deg,
            zoom: 1.0,
            projection: Projection::Orthographic,
        }
    }
}

impl Default for Camera {
    fn default() -> Self {
        Self::view(View::Iso)
    }
}

/// An axis-aligned clipping plane for cross-sections: the voxels with coordinate on
/// `axis` at or above `at` are removed (or below it, when `keep_above`). The removed
/// voxels are gone for every ray, shadows included (see [`crop_to_clip`](super::crop_to_clip)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clip {
    /// 0 for x, 1 for y, 2 for z.
    pub axis: usize,
    /// The plane's coordinate, in voxels.
    pub at: f64,
    /// Keep the part above the plane instead of below.
    pub keep_above: bool,
}

/// Everything that decides how an image looks.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The camera.
    pub camera: Camera,
    /// Draw the outlines of the octree's black blocks.
    pub outline: bool,
    /// Draw a ground plane under the solid, with the solid's shadow (and shadows on
    /// the solid itself).
    pub shadows: bool,
    /// Ambient-occlusion rays per pixel (0: none).
    pub ao_samples: u32,
    /// A cross-section plane.
    pub clip: Option<Clip>,
    /// The background colour.
    pub background: [u8; 3],
    /// How surfaces are shaded.
    pub normals: Normals,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            camera: Camera::default(),
            outline: false,
            shadows: true,
            ao_samples: 0,
            clip: None,
            background: [250, 250, 252],
            normals: Normals::Auto,
        }
    }
}

/// The colour of the solid at a point (voxel coordinates), e.g. a scene's
/// per-object colours.
pub type Shader<'a> = &'a (dyn Fn([f64; 3]) -> [u8; 3] + Sync);

/// An outward unit normal of the solid near a point (voxel coordinates), when known:
/// e.g. [`crate::csg::Csg::normal_at`].
pub type NormalFn<'a> = &'a (dyn Fn([f64; 3]) -> Option<[f64; 3]> + Sync);

/// What the renderer may ask about the solid beyond its octree: colours and normals.
/// Both are optional; an octree file alone is drawn in [`DEFAULT_COLOUR`] with normals
/// estimated from the octree.
#[derive(Clone, Copy, Default)]
pub struct Surface<'a> {
    /// The colour at a point inside the solid.
    pub colour: Option<Shader<'a>>,
    /// The normal at a point on the surface.
    pub normal: Option<NormalFn<'a>>,
}

/// How surfaces are shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Normals {
    /// Smooth where voxels are smaller than two pixels, block faces otherwise.
    #[default]
    Auto,
    /// The faces of the blocks: the octree as it is.
    Faces,
    /// Smooth: the surface's own normal when given, else the gradient of the octree's
    /// occupancy around the hit.
    Smooth,
}

/// The colour used when no shader is given.
pub const DEFAULT_COLOUR: [u8; 3] = [150, 165, 185];
