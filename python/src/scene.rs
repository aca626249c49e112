//! `tesseral.Scene` and `tesseral.render`.

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray3, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use tesseral::csg::Scene as CsgScene;
use tesseral::model::Model;
use tesseral::render::{self as draw, Camera, Image, Projection, RenderOptions, View};

use crate::args::{int_within, ints_within, Int};
use crate::errors;
use crate::occupancy::OccupancyMap;
use crate::octree::Octree;

/// The depths a scene may be built at.
const DEPTHS: std::ops::RangeInclusive<i64> = 1..=16;

/// A parsed `.tss` scene (see docs/scenes.md).
#[pyclass(module = "tesseral", frozen)]
pub struct Scene {
    scene: CsgScene,
    /// The source text and its path, kept for pickling.
    text: String,
    path: PathBuf,
}

#[pymethods]
impl Scene {
    /// Parses scene text; errors raise SceneError with `line` and `column`.
    #[staticmethod]
    fn parse(py: Python<'_>, text: &str) -> PyResult<Scene> {
        Scene::from_text(py, text.to_owned(), PathBuf::from("<scene>"))
    }

    /// Reads a `.tss` file.
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Scene> {
        let scene = CsgScene::read(&path).map_err(|e| errors::scene(py, e))?;
        // It parsed, so it was read and is UTF-8.
        let text = std::fs::read_to_string(&path).map_err(|e| errors::io(&e, Some(&path)))?;
        Ok(Scene { scene, text, path })
    }

    /// The scene parsed from `text` as if read from `path` (pickling's way back).
    #[staticmethod]
    fn _from_text(py: Python<'_>, text: String, path: PathBuf) -> PyResult<Scene> {
        Scene::from_text(py, text, path)
    }

    /// Pickling: the source text and path.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String, PathBuf))> {
        let f = py.get_type::<Scene>().getattr("_from_text")?;
        Ok((f, (self.text.clone(), self.path.clone())))
    }

    /// Builds the scene's octree with its frame and colours, at the scene's depth or
    /// at `depth` (1 to 16: the same bounds, coarser or finer voxels; ValueError
    /// outside).
    #[pyo3(signature = (depth = None))]
    fn build(&self, py: Python<'_>, depth: Option<&Bound<'_, PyAny>>) -> PyResult<Octree> {
        // Checked here, not converted by pyo3, whose OverflowError names neither.
        let depth = match depth {
            Some(d) => Some(
                int_within(d, "depth", DEPTHS)?
                    .ok_or_else(|| PyValueError::new_err(format!("depth {d}: expected 1 to 16")))?
                    as u8,
            ),
            None => None,
        };
        let scene = self.at_depth(depth)?;
        py.allow_threads(|| scene.build_model_limited(tesseral::csg::DEFAULT_MAX_LEAVES))
            .map(Octree::new)
            .map_err(|e| errors::scene(py, e))
    }

    /// Depth of the scene's space.
    #[getter]
    fn depth(&self) -> u8 {
        self.scene.depth
    }

    /// The number of top-level objects.
    #[getter]
    fn objects(&self) -> usize {
        self.scene.objects
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({}, depth {}, voxel {})",
            crate::count(self.scene.objects as u64, "object", "objects"),
            self.scene.depth,
            self.scene.voxel
        )
    }

    /// A PNG picture, for Jupyter.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let img = render_scene(py, &self.scene, &Options::default())?;
        png(py, &img)
    }
}

impl Scene {
    fn from_text(py: Python<'_>, text: String, path: PathBuf) -> PyResult<Scene> {
        let scene = CsgScene::parse(&text, &path).map_err(|e| errors::scene(py, e))?;
        Ok(Scene { scene, text, path })
    }

    /// The scene at its own depth or at `depth` (1 to 16: the same bounds, coarser
    /// or finer voxels).
    pub fn at_depth(&self, depth: Option<u8>) -> PyResult<CsgScene> {
        let mut s = self.scene.clone();
        if let Some(d) = depth {
            if !DEPTHS.contains(&i64::from(d)) {
                return Err(PyValueError::new_err(format!(
                    "depth {d}: expected 1 to 16"
                )));
            }
            s.voxel *= 2f64.powi(i32::from(s.depth) - i32::from(d));
            s.depth = d;
        }
        Ok(s)
    }
}

/// A scene depth argument, 1 to 16 (ValueError naming `depth` outside, however
/// far), or None for the scene's own.
pub fn scene_depth(depth: Option<&Int>) -> PyResult<Option<u8>> {
    depth
        .map(|d| d.within("depth", 1..=16, "expected 1 to 16"))
        .transpose()
}

/// The render options a Python call can give.
pub struct Options {
    pub size: (usize, usize),
    pub view: View,
    pub azimuth: Option<f64>,
    pub elevation: Option<f64>,
    pub zoom: f64,
    pub outline: bool,
    pub shadows: bool,
    pub perspective: Option<f64>,
    pub background: [u8; 3],
}

impl Default for Options {
    fn default() -> Self {
        Options {
            size: (480, 360),
            view: View::Iso,
            azimuth: None,
            elevation: None,
            zoom: 1.0,
            outline: false,
            shadows: true,
            perspective: None,
            background: [255, 255, 255],
        }
    }
}

impl Options {
    fn render_options(&self) -> RenderOptions {
        let (az, el) = self.view.angles();
        RenderOptions {
            width: self.size.0,
            height: self.size.1,
            camera: Camera {
                azimuth_deg: self.azimuth.unwrap_or(az),
                elevation_deg: self.elevation.unwrap_or(el),
                zoom: self.zoom,
                projection: self
                    .perspective
                    .map_or(Projection::Orthographic, |fov_deg| {
                        Projection::Perspective { fov_deg }
                    }),
            },
            outline: self.outline,
            shadows: self.shadows,
            background: self.background,
            ..RenderOptions::default()
        }
    }
}

/// A model drawn with its stored colours.
pub fn render_model(py: Python<'_>, m: &Model, o: &Options) -> PyResult<Image> {
    let opts = o.render_options();
    Ok(py.allow_threads(|| {
        let stored = m.colors.as_ref().map(|l| {
            move |p: [f64; 3]| {
                l.get(p.map(|c| c.floor() as i64))
                    .map_or(draw::DEFAULT_COLOUR, |c| [c[0], c[1], c[2]])
            }
        });
        let surface = draw::Surface {
            colour: stored
                .as_ref()
                .map(|f| f as &(dyn Fn([f64; 3]) -> [u8; 3] + Sync)),
            normal: None,
        };
        draw::render(&m.tree, surface, &opts)
    }))
}

/// A scene drawn with its objects' colours and exact normals.
fn render_scene(py: Python<'_>, scene: &CsgScene, o: &Options) -> PyResult<Image> {
    let csg = scene.csg().map_err(|e| errors::scene(py, e))?;
    let tree = py
        .allow_threads(|| scene.build())
        .map_err(|e| errors::scene(py, e))?;
    let opts = o.render_options();
    Ok(py.allow_threads(|| {
        let colour = |p: [f64; 3]| csg.colour_at(p).map_or(draw::DEFAULT_COLOUR, |k| k.0);
        let normal = |p: [f64; 3]| csg.normal_at(p);
        let surface = draw::Surface {
            colour: Some(&colour),
            normal: Some(&normal),
        };
        draw::render(&tree, surface, &opts)
    }))
}

/// PNG bytes of an image.
pub fn png<'py>(py: Python<'py>, img: &Image) -> PyResult<Bound<'py, PyBytes>> {
    let mut buf = Vec::new();
    img.encode_png(&mut buf)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(PyBytes::new(py, &buf))
}

/// The camera's numbers checked as the CLI checks `--azimuth`, `--elevation`,
/// `--zoom` and `--fov`, each error naming its argument: NaN, an infinity or a
/// field of view of 0 or 180 degrees would draw a blank or a wrong picture.
fn check_camera(
    azimuth: Option<f64>,
    elevation: Option<f64>,
    zoom: f64,
    perspective: Option<f64>,
) -> PyResult<()> {
    let refuse = |why: String| Err(PyValueError::new_err(why));
    for (name, value) in [("azimuth", azimuth), ("elevation", elevation)] {
        if let Some(v) = value.filter(|v| !v.is_finite()) {
            return refuse(format!("{name} {v}: must be a finite number of degrees"));
        }
    }
    if let Some(e) = elevation.filter(|e| e.abs() > 90.0) {
        return refuse(format!(
            "elevation {e}: must lie between -90 and 90 degrees"
        ));
    }
    if !(zoom.is_finite() && zoom > 0.0) {
        return refuse(format!("zoom {zoom}: must be a positive finite number"));
    }
    if let Some(f) = perspective.filter(|f| !(*f > 0.0 && *f < 180.0)) {
        return refuse(format!(
            "perspective {f}: the field of view must lie between 0 and 180 degrees"
        ));
    }
    Ok(())
}

/// Renders an Octree, a Scene or an OccupancyMap (its `to_octree()`) as an H×W×3
/// uint8 array. Keyword arguments are the CLI's options: size=(w, h), view ('iso',
/// 'front', 'top', 'side'), azimuth, elevation (-90 to 90), zoom (positive),
/// outline, shadows, perspective (field of view in degrees, between 0 and 180),
/// background (r, g, b, each 0 to 255). A value out of its range, or a NaN or
/// infinite angle or zoom, raises ValueError naming it.
#[pyfunction]
#[pyo3(signature = (obj, size = None, view = "iso", azimuth = None, elevation = None, zoom = 1.0, outline = false, shadows = true, perspective = None, background = None),
       text_signature = "(obj, size=(800, 600), view='iso', azimuth=None, elevation=None, zoom=1.0, outline=False, shadows=True, perspective=None, background=(255, 255, 255))")]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    size: Option<&Bound<'py, PyAny>>,
    view: &str,
    azimuth: Option<f64>,
    elevation: Option<f64>,
    zoom: f64,
    outline: bool,
    shadows: bool,
    perspective: Option<f64>,
    background: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    // What is drawn is checked first: a wrong object is a TypeError whatever the options.
    let octree = obj.downcast::<Octree>().ok();
    let scene = obj.downcast::<Scene>().ok();
    let map = obj.downcast::<OccupancyMap>().ok();
    if octree.is_none() && scene.is_none() && map.is_none() {
        return Err(PyTypeError::new_err(format!(
            "render takes an Octree, a Scene or an OccupancyMap, got {}",
            obj.get_type().name()?
        )));
    }
    let view = View::parse(view).ok_or_else(|| {
        PyValueError::new_err(format!("view {view:?}: expected iso, front, top or side"))
    })?;
    // Checked here, not converted by pyo3, whose OverflowError names neither.
    let [width, height] = match size {
        Some(s) => ints_within(s, "size", 16..=8192, "each side must be 16 to 8192 pixels")?,
        None => [800, 600],
    };
    let [r, g, b] = match background {
        Some(c) => ints_within(
            c,
            "background",
            0..=255,
            "each channel (r, g, b) must be 0 to 255",
        )?,
        None => [255; 3],
    };
    check_camera(azimuth, elevation, zoom, perspective)?;
    // In range, checked above.
    let o = Options {
        size: (width as usize, height as usize),
        view,
        azimuth,
        elevation,
        zoom,
        outline,
        shadows,
        perspective,
        background: [r as u8, g as u8, b as u8],
    };
    let img = if let Some(t) = octree {
        render_model(py, &t.get().model, &o)?
    } else if let Some(s) = scene {
        render_scene(py, &s.get().scene, &o)?
    } else {
        let map = map.expect("checked above");
        let this = errors::borrow(map, "OccupancyMap")?;
        let m = &this.map;
        let model = py.allow_threads(|| m.to_model()).map_err(errors::octree)?;
        render_model(py, &model, &o)?
    };
    let (w, h) = (img.width, img.height);
    let flat: Vec<u8> = img.pixels.into_iter().flatten().collect();
    flat.into_pyarray(py).reshape([h, w, 3])
}
