//! The native half of the Python package `formation` (`formation._native`): thin bindings over
//! the library's pipeline. Options arrive as `(option path, JSON value)` pairs and are merged
//! into the library's serde-ready [`Config`], so every option the library has is reachable from
//! Python under its own path (`steady.fps`) without a binding per option. Library errors become
//! `ValueError` (bad input) or `OSError` (a file that cannot be read or written) with the
//! library's one-line message; long stages run with the GIL released.

use std::path::PathBuf;

use formation::animation::Animation;
use formation::annotations::{self, Annotations, Heading, ReadOptions};
use formation::error::one_line;
use formation::extract::FormationParams;
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;
use formation::Error;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::Value;

/// The `formation` binary's own code (`src/main.rs` and `src/cli/`), compiled in so that the
/// wheel's `formation` command is the same program as `cargo install`'s.
#[allow(dead_code)]
#[path = "../../src/main.rs"]
mod cli_main;

mod pickle;

/// A library error as a Python exception carrying the library's one-line message.
fn py_err(e: Error) -> PyErr {
    let message = one_line(&e.to_string());
    match e {
        Error::Io { source, .. } => {
            PyOSError::new_err((source.raw_os_error().unwrap_or(0), message))
        }
        _ => PyValueError::new_err(message),
    }
}

/// Sets `value` at the dotted `name` inside `root`; an unknown name is reported with the valid
/// ones.
fn set_path(root: &mut Value, name: &str, value: Value) -> Result<(), String> {
    let mut node = root;
    let mut parts = name.split('.').peekable();
    let mut walked = String::new();
    while let Some(part) = parts.next() {
        let Value::Object(map) = node else {
            return Err(format!(
                "{name}: unknown option ({walked} is a value, not a section)"
            ));
        };
        if !map.contains_key(part) {
            let mut known: Vec<&str> = map.keys().map(String::as_str).collect();
            known.sort_unstable();
            let within = if walked.is_empty() {
                "the options are".to_string()
            } else {
                format!("{walked} has")
            };
            return Err(format!(
                "{name}: unknown option; {within}: {}",
                known.join(", ")
            ));
        }
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(part);
        let slot = map.get_mut(part).expect("checked above");
        if parts.peek().is_none() {
            *slot = value;
            return Ok(());
        }
        node = slot;
    }
    Err(format!("{name}: empty option name"))
}

/// The leaves of `value` given at `name`: a dict given for a section is split into one option
/// per key (recursively), so that each is checked and named on its own.
fn leaves(root: &Value, name: &str, value: Value, out: &mut Vec<(String, Value)>) {
    let slot = name.split('.').try_fold(root, |node, part| {
        node.as_object().and_then(|m| m.get(part))
    });
    match (slot, value) {
        (Some(Value::Object(_)), Value::Object(map)) => {
            for (k, v) in map {
                leaves(root, &format!("{name}.{k}"), v, out);
            }
        }
        (_, value) => out.push((name.to_string(), value)),
    }
}

/// `root` with the option `leaf` set to `value` when `leaf` names a field its section leaves
/// out of the serialised form at its default (such as `aero.wake` when planar): the section
/// must reject unknown fields (checked with a name no section has) and accept this one.
/// `Ok(None)`: not such a field; `Err`: the field exists but `value` is not one of its values.
fn set_hidden<T: DeserializeOwned>(
    root: &Value,
    leaf: &str,
    value: Value,
) -> Result<Option<Value>, String> {
    let (parent, last) = match leaf.rsplit_once('.') {
        Some((p, l)) => (Some(p), l),
        None => (None, leaf),
    };
    let with = |key: &str, v: Value| -> Option<Value> {
        let mut out = root.clone();
        let section = match parent {
            Some(p) => p
                .split('.')
                .try_fold(&mut out, |node, part| node.get_mut(part))?,
            None => &mut out,
        };
        let map = section.as_object_mut()?;
        if map.contains_key(key) {
            return None;
        }
        map.insert(key.to_string(), v);
        Some(out)
    };
    let Some(probe) = with("__no_such_option__", Value::Null) else {
        return Ok(None);
    };
    if serde_json::from_value::<T>(probe).is_ok() {
        return Ok(None);
    }
    let Some(candidate) = with(last, value) else {
        return Ok(None);
    };
    match serde_json::from_value::<T>(candidate.clone()) {
        Ok(_) => Ok(Some(candidate)),
        Err(e) if e.to_string().contains("unknown field") => Ok(None),
        Err(e) => Err(e.to_string()),
    }
}

/// `base` with every `(option path, JSON text)` pair applied in order, checked by the type's
/// own deserializer after each option so that a bad value is named by its path.
fn merged<T: Serialize + DeserializeOwned>(
    base: &T,
    options: &[(String, String)],
    prefix: &str,
) -> PyResult<T> {
    let invalid = |e: serde_json::Error| PyValueError::new_err(e.to_string());
    let mut value = serde_json::to_value(base).map_err(invalid)?;
    let mut out = serde_json::from_value::<T>(value.clone()).map_err(invalid)?;
    for (name, text) in options {
        let new: Value = serde_json::from_str(text)
            .map_err(|e| PyValueError::new_err(format!("{prefix}{name}: {e}")))?;
        let mut each = Vec::new();
        leaves(&value, name, new, &mut each);
        for (leaf, new) in each {
            // Sections serialise every field but those left out at their default (such as
            // `aero.wake` when planar), so an unknown name is caught by the walk or the probe.
            if let Err(e) = set_path(&mut value, &leaf, new.clone()) {
                match set_hidden::<T>(&value, &leaf, new) {
                    Ok(Some(v)) => value = v,
                    Ok(None) => return Err(PyValueError::new_err(format!("{prefix}{e}"))),
                    Err(bad) => {
                        return Err(PyValueError::new_err(format!(
                            "{prefix}{leaf}: {}",
                            one_line(&bad)
                        )))
                    }
                }
            }
            out = serde_json::from_value::<T>(value.clone()).map_err(|e| {
                PyValueError::new_err(format!("{prefix}{leaf}: {}", one_line(&e.to_string())))
            })?;
        }
    }
    Ok(out)
}

/// The run's [`Config`] from option pairs.
fn config(options: &[(String, String)]) -> PyResult<Config> {
    merged(&Config::default(), options, "")
}

fn pipeline(input: &Bound<'_, PyAny>) -> PyResult<Pipeline> {
    if let Ok(a) = input.cast::<PyAnnotations>() {
        return Ok(Pipeline::from_annotations(a.get().inner.clone()));
    }
    if let Ok(p) = input.cast::<PyParams>() {
        return Ok(Pipeline::from_params(p.get().inner.clone()));
    }
    let path: PathBuf = input.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "input: expected a path, Annotations or Params, got {}",
            input
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    Ok(Pipeline::from_path(path))
}

/// JSON text to a Python object (dicts, lists, numbers, strings).
fn json_to_py<'py>(py: Python<'py>, v: &impl Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Annotated frames, read from a file or built from points in memory.
#[pyclass(name = "Annotations", module = "formation", frozen)]
struct PyAnnotations {
    inner: Annotations,
}

#[pymethods]
impl PyAnnotations {
    /// The file or directory read (or the source name of points given in memory).
    #[getter]
    fn path(&self) -> PathBuf {
        self.inner.path.clone()
    }
    /// Free text describing the footage, or the file name.
    #[getter]
    fn source(&self) -> String {
        self.inner.source.clone()
    }
    /// The detected input format (`native`, `longcsv`, `dltdv`, `labelme`, ...).
    #[getter]
    fn format(&self) -> PyResult<String> {
        Ok(serde_json::to_value(self.inner.format)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default())
    }
    /// Number of annotated frames.
    fn __len__(&self) -> usize {
        self.inner.frames.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "Annotations({:?}, {} frames)",
            self.inner.source,
            self.inner.frames.len()
        )
    }
    /// Equal when every frame, point and setting is.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyAnnotations>()
            .is_ok_and(|o| o.get().inner == self.inner)
    }
    /// Pickles as the annotations' JSON (exact: the shortest text of each number).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py>> {
        let state =
            serde_json::to_vec(&self.inner).map_err(|e| PyValueError::new_err(e.to_string()))?;
        reduced(py, "Annotations", state)
    }
    /// Immutable: a copy is the object itself.
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }
    /// Immutable: a deep copy is the object itself.
    fn __deepcopy__(slf: Py<Self>, _memo: &Bound<'_, PyAny>) -> Py<Self> {
        slf
    }
}

/// Formation parameters extracted from annotations (or read from a params file).
#[pyclass(name = "Params", module = "formation", frozen)]
struct PyParams {
    inner: FormationParams,
}

#[pymethods]
impl PyParams {
    /// The file format tag.
    #[getter]
    fn format(&self) -> String {
        self.inner.format.clone()
    }
    /// Free text from the annotations.
    #[getter]
    fn source(&self) -> String {
        self.inner.source.clone()
    }
    /// Number of distinct birds in the footage.
    #[getter]
    fn birds(&self) -> usize {
        self.inner.birds
    }
    /// One dict per annotated frame: index, order, leader, mu_x, sigma_x, model, ...
    #[getter]
    fn frames<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.inner.frames)
    }
    /// Geometry over all frames and the extraction's warnings (a dict), or None.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.inner.summary)
    }
    /// Everything as a dict, as the params JSON file holds it.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.inner)
    }
    /// The params JSON text (what `formation extract -o params.json` writes).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.inner).map_err(|e| PyValueError::new_err(e.to_string()))
    }
    fn __repr__(&self) -> String {
        format!(
            "Params({:?}, {} birds, {} frames)",
            self.inner.source,
            self.inner.birds,
            self.inner.frames.len()
        )
    }
    /// Equal when every frame's parameters and the summary are.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyParams>()
            .is_ok_and(|o| o.get().inner == self.inner)
    }
    /// Pickles as the params JSON (exact: the shortest text of each number).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py>> {
        let state =
            serde_json::to_vec(&self.inner).map_err(|e| PyValueError::new_err(e.to_string()))?;
        reduced(py, "Params", state)
    }
    /// Immutable: a copy is the object itself.
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }
    /// Immutable: a deep copy is the object itself.
    fn __deepcopy__(slf: Py<Self>, _memo: &Bound<'_, PyAny>) -> Py<Self> {
        slf
    }
}

/// A flock's motion: every bird at every frame.
#[pyclass(name = "Animation", module = "formation", frozen)]
struct PyAnimation {
    inner: Animation,
    config: Config,
}

impl PyAnimation {
    fn per_bird(&self, f: impl Fn(&formation::animation::Frame, usize) -> f64) -> Array2<f64> {
        let (n, b) = (self.inner.frames.len(), self.inner.birds);
        Array2::from_shape_fn((n, b), |(k, i)| f(&self.inner.frames[k], i))
    }
}

fn opt_at(v: &Option<Vec<f64>>, i: usize, missing: f64) -> f64 {
    v.as_ref()
        .and_then(|v| v.get(i))
        .copied()
        .unwrap_or(missing)
}

#[pymethods]
impl PyAnimation {
    /// Number of birds.
    #[getter]
    fn birds(&self) -> usize {
        self.inner.birds
    }
    /// Frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        self.inner.fps
    }
    /// The seed the animation was made with.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }
    /// One wingspan in metres.
    #[getter]
    fn wingspan_m(&self) -> f64 {
        self.inner.wingspan_m
    }
    /// The species whose wingbeat is used, or None.
    #[getter]
    fn species(&self) -> Option<String> {
        self.inner.species.clone()
    }
    /// The stages as (name, first frame, end frame exclusive) tuples, e.g.
    /// [("initiation", 0, 312), ("steady", 312, 712)].
    #[getter]
    fn stages(&self) -> Vec<(String, usize, usize)> {
        self.inner
            .stages
            .iter()
            .map(|s| (s.name.as_str().to_string(), s.start, s.end))
            .collect()
    }
    /// Number of frames.
    fn __len__(&self) -> usize {
        self.inner.frames.len()
    }
    /// Time of each frame, seconds (frames,), float64.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.frames.iter().map(|f| f.t)).into_pyarray(py)
    }
    /// World positions x east, y north, z up, wingspans (frames, birds, 3), float64.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let (n, b) = (self.inner.frames.len(), self.inner.birds);
        Array3::from_shape_fn((n, b, 3), |(k, i, c)| {
            let f = &self.inner.frames[k];
            let v = match c {
                0 => &f.x,
                1 => &f.y,
                _ => &f.z,
            };
            v.get(i).copied().unwrap_or(f64::NAN)
        })
        .into_pyarray(py)
    }
    /// Headings, radians clockwise from north (frames, birds).
    #[getter]
    fn headings<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| f.heading.get(i).copied().unwrap_or(f64::NAN))
            .into_pyarray(py)
    }
    /// Ground speeds, wingspans per second (frames, birds).
    #[getter]
    fn speeds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| f.speed.get(i).copied().unwrap_or(f64::NAN))
            .into_pyarray(py)
    }
    /// Bank angles, radians, right wing down positive; 0 where level (frames, birds).
    #[getter]
    fn banks<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| opt_at(&f.bank, i, 0.0))
            .into_pyarray(py)
    }
    /// Pitch angles, radians, nose up positive; 0 where level (frames, birds).
    #[getter]
    fn pitches<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| opt_at(&f.pitch, i, 0.0))
            .into_pyarray(py)
    }
    /// Wingbeat phase, radians in [0, 2π), 0 = start of the downstroke; NaN where the
    /// animation has none (frames, birds).
    #[getter]
    fn wing_phase<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| opt_at(&f.wing_phase, i, f64::NAN))
            .into_pyarray(py)
    }
    /// Each bird's saving e: the fraction of its solo induced power the others save it (the
    /// CSV's `e` column); NaN where undefined (frames, birds).
    #[getter]
    fn savings<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| opt_at(&f.e, i, f64::NAN))
            .into_pyarray(py)
    }
    /// Each bird's relative saving ξ = e / Σe (the CSV's `xi` column); NaN where undefined
    /// (frames, birds).
    #[getter]
    fn xi<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_bird(|f, i| opt_at(&f.xi, i, f64::NAN))
            .into_pyarray(py)
    }
    /// The CSV text `formation animate -o out.csv` writes (one row per frame and bird).
    fn to_csv(&self, py: Python<'_>) -> PyResult<String> {
        let mut buf = Vec::new();
        py.detach(|| formation::export::table::write_csv(&self.inner, &mut buf))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        String::from_utf8(buf).map_err(|e| PyValueError::new_err(e.to_string()))
    }
    /// The animation JSON text (what `formation animate -o out.json` writes).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner).map_err(|e| PyValueError::new_err(e.to_string()))
    }
    /// A tidy pandas DataFrame with exactly the CSV's columns (pandas is imported here only).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pandas = py.import("pandas").map_err(|_| {
            pyo3::exceptions::PyImportError::new_err(
                "Animation.to_pandas needs pandas, which is not installed: pip install pandas (or install the package as \"formation[pandas]\"); the arrays (positions, savings, ...) need only numpy",
            )
        })?;
        let csv = self.to_csv(py)?;
        let text = py.import("io")?.call_method1("StringIO", (csv,))?;
        pandas.call_method1("read_csv", (text,))
    }
    /// Writes the animation to every path given, each format told by its extension as with
    /// `formation animate -o`: .json, .csv, .glb, .gif, .mp4/.webm, .usda, a PNG frames
    /// directory, ... `options` override the run's `render.*` options (`width=640` or
    /// `**{"render.width": 640}`). Raises ValueError or OSError; no partial file is left.
    #[pyo3(signature = (*paths, **options))]
    fn write(
        &self,
        py: Python<'_>,
        paths: &Bound<'_, pyo3::types::PyTuple>,
        options: Option<&Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<()> {
        let paths: Vec<PathBuf> = paths.extract()?;
        if paths.is_empty() {
            return Err(PyValueError::new_err(
                "write: give at least one output path",
            ));
        }
        let pairs: Vec<(String, String)> = match options {
            Some(o) => py
                .import("formation")?
                .getattr("_pairs")?
                .call1((o, "render."))?
                .extract()?,
            None => Vec::new(),
        };
        let render = merged(&self.config.render, &pairs, "render.")?;
        py.detach(|| formation::export::write_outputs(&self.inner, &paths, &render, &Silent))
            .map_err(py_err)
    }
    /// A notebook cell's view: a summary table and the 3-D player (the page `formation view`
    /// writes) in an isolated frame; above `NOTEBOOK_PLAYER_BIRD_FRAMES` bird-frames, frames
    /// are thinned (the player interpolates between those kept).
    fn _repr_html_(&self) -> PyResult<String> {
        notebook_html(&self.inner)
    }
    fn __repr__(&self) -> String {
        format!(
            "Animation({} birds, {} frames at {} fps, {:.2} s)",
            self.inner.birds,
            self.inner.frames.len(),
            self.inner.fps,
            self.inner.frames.last().map_or(0.0, |f| f.t)
        )
    }
    /// Equal when every frame of every bird, the stages, key shapes and the rest of the file,
    /// and the run's options (which `write` uses) are.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyAnimation>().is_ok_and(|o| {
            let o = o.get();
            o.inner == self.inner && o.config == self.config
        })
    }
    /// Pickles exactly: the frames as their raw 64-bit values (not the JSON file's rounded
    /// text), with the run's options.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py>> {
        let state = py
            .detach(|| pickle::animation_state(&self.inner, &self.config))
            .map_err(PyValueError::new_err)?;
        reduced(py, "Animation", state)
    }
    /// Immutable: a copy is the object itself.
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }
    /// Immutable: a deep copy is the object itself.
    fn __deepcopy__(slf: Py<Self>, _memo: &Bound<'_, PyAny>) -> Py<Self> {
        slf
    }
}

/// What `__reduce__` returns: `formation._unpickle` and its arguments (the class's name and its
/// state).
type Reduced<'py> = (
    Bound<'py, PyAny>,
    (&'static str, Bound<'py, pyo3::types::PyBytes>),
);

fn reduced<'py>(py: Python<'py>, kind: &'static str, state: Vec<u8>) -> PyResult<Reduced<'py>> {
    let unpickle = py.import("formation")?.getattr("_unpickle")?;
    Ok((unpickle, (kind, pyo3::types::PyBytes::new(py, &state))))
}

/// A `Params`, `Animation` or `Annotations` from the state its `__reduce__` gave.
#[pyfunction]
fn from_state(py: Python<'_>, kind: &str, state: &[u8]) -> PyResult<Py<PyAny>> {
    let bad = |e: String| PyValueError::new_err(format!("unpickling a formation.{kind}: {e}"));
    match kind {
        "Params" => {
            let inner = serde_json::from_slice(state).map_err(|e| bad(e.to_string()))?;
            Ok(Py::new(py, PyParams { inner })?.into_any())
        }
        "Annotations" => {
            let inner = serde_json::from_slice(state).map_err(|e| bad(e.to_string()))?;
            Ok(Py::new(py, PyAnnotations { inner })?.into_any())
        }
        "Animation" => {
            let (inner, config) = py
                .detach(|| pickle::animation_from_state(state))
                .map_err(bad)?;
            Ok(Py::new(py, PyAnimation { inner, config })?.into_any())
        }
        _ => Err(PyValueError::new_err(format!(
            "unpickling: `{kind}` is not a formation class (Params, Animation or Annotations)"
        ))),
    }
}

/// Progress handed to a Python callable `callback(stage, done, total)`: at the start of each
/// stage, at most every [`CALLBACK_EVERY`] while it runs, and at its end. The pipeline runs
/// with the GIL released; each call takes it for the call's length. The first exception the
/// callable raises is kept and raised when the run ends (later calls are skipped).
struct CallbackProgress {
    callback: Py<PyAny>,
    state: std::sync::Mutex<CallbackState>,
}

struct CallbackState {
    stage: String,
    done: u64,
    total: u64,
    last: Option<std::time::Instant>,
    error: Option<PyErr>,
}

/// Shortest interval between two calls of a progress callable while a stage runs.
const CALLBACK_EVERY: std::time::Duration = std::time::Duration::from_millis(100);

impl CallbackProgress {
    fn new(callback: Py<PyAny>) -> Self {
        CallbackProgress {
            callback,
            state: std::sync::Mutex::new(CallbackState {
                stage: String::new(),
                done: 0,
                total: 0,
                last: None,
                error: None,
            }),
        }
    }

    /// Calls the callable with the state (holding the state's lock, so calls never overlap).
    fn call(&self, st: &mut CallbackState) {
        if st.error.is_some() {
            return;
        }
        st.last = Some(std::time::Instant::now());
        let args = (st.stage.clone(), st.done.min(st.total), st.total);
        if let Err(e) = Python::attach(|py| self.callback.call1(py, args).map(|_| ())) {
            st.error = Some(e);
        }
    }

    fn take_error(&self) -> Option<PyErr> {
        self.state.lock().ok().and_then(|mut s| s.error.take())
    }
}

impl formation::progress::Progress for CallbackProgress {
    fn start(&self, stage: &str, total: u64) {
        if let Ok(mut st) = self.state.lock() {
            st.stage = stage.to_string();
            st.done = 0;
            st.total = total;
            self.call(&mut st);
        }
    }

    fn advance(&self, n: u64) {
        if let Ok(mut st) = self.state.lock() {
            st.done = st.done.saturating_add(n);
            let due = st.last.map_or(true, |t| t.elapsed() >= CALLBACK_EVERY);
            if due || st.done >= st.total {
                self.call(&mut st);
            }
        }
    }

    fn finish(&self) {
        if let Ok(mut st) = self.state.lock() {
            st.done = st.total;
            self.call(&mut st);
        }
    }
}

/// Most bird-frames the notebook view embeds before it thins frames (about 20 bytes each in
/// the page: a 30 MB cell at most).
const NOTEBOOK_PLAYER_BIRD_FRAMES: usize = 1_500_000;

fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + s.len() / 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The HTML an `Animation` shows in a notebook cell: what it is (birds, frames, stages, the
/// clearance) and the player in an `<iframe srcdoc>`, so its script and styles cannot touch the
/// notebook's.
fn notebook_html(anim: &Animation) -> PyResult<String> {
    let bird_frames = anim.birds * anim.frames.len();
    let every = bird_frames.div_ceil(NOTEBOOK_PLAYER_BIRD_FRAMES).max(1);
    let mut rows = String::new();
    let seconds = anim.frames.len() as f64 / anim.fps;
    rows.push_str(&format!(
        "<tr><th>birds</th><td>{}</td></tr><tr><th>frames</th><td>{} at {} fps ({:.1} s)</td></tr>",
        anim.birds,
        anim.frames.len(),
        anim.fps,
        seconds
    ));
    if let Some(species) = &anim.species {
        rows.push_str(&format!(
            "<tr><th>species</th><td>{}</td></tr>",
            html_escape(species)
        ));
    }
    let stages: Vec<String> = anim
        .stages
        .iter()
        .map(|s| format!("{} {:.1} s", s.name, (s.end - s.start) as f64 / anim.fps))
        .collect();
    if !stages.is_empty() {
        rows.push_str(&format!(
            "<tr><th>stages</th><td>{}</td></tr>",
            html_escape(&stages.join(", "))
        ));
    }
    let clearance = cli_main::cli::summary::clearance_text(anim);
    rows.push_str(&format!(
        "<tr><th>clearance</th><td>{}</td></tr>",
        html_escape(clearance.trim_start_matches("; clearance: "))
    ));
    let player = if anim.frames.is_empty() || anim.birds == 0 {
        String::new()
    } else {
        let opts = formation::player::PlayerOptions {
            title: "animation".into(),
            start_frame: None,
            every: every.min(formation::player::MAX_EVERY),
        };
        let page = formation::player::page(anim, &opts).map_err(py_err)?;
        let thinned = if every > 1 {
            format!(
                "<p style=\"margin:2px 0;font-size:90%\">every {every}th frame kept in this view (the player interpolates); <code>formation view</code> writes them all</p>"
            )
        } else {
            String::new()
        };
        format!(
            "{thinned}<iframe srcdoc=\"{}\" style=\"width:100%;height:520px;border:1px solid #ccc\" sandbox=\"allow-scripts\"></iframe>",
            html_escape(&page)
        )
    };
    Ok(format!(
        "<div><table style=\"font-size:90%\"><caption style=\"text-align:left\"><b>formation.Animation</b></caption>{rows}</table>{player}</div>"
    ))
}

/// Runs the whole pipeline (see `formation.animate`); `progress`: the command line's progress
/// bar on stderr (drawn only when stderr is a terminal); `callback`: a callable given the
/// progress instead (`callback(stage, done, total)`).
#[pyfunction]
#[pyo3(signature = (input, options, progress, callback=None))]
fn animate(
    py: Python<'_>,
    input: &Bound<'_, PyAny>,
    options: Vec<(String, String)>,
    progress: bool,
    callback: Option<Py<PyAny>>,
) -> PyResult<(PyAnimation, Vec<String>)> {
    let pipeline = pipeline(input)?;
    let config = config(&options)?;
    let (anim, report) = match callback {
        Some(callback) => {
            let bar = CallbackProgress::new(callback);
            let out = py.detach(|| pipeline.run_with(&config, &bar));
            if let Some(e) = bar.take_error() {
                return Err(e);
            }
            out.map_err(py_err)?
        }
        None => {
            let bar = cli_main::cli::progress::TermProgress::new(!progress);
            py.detach(|| pipeline.run_with(&config, &bar))
                .map_err(py_err)?
        }
    };
    // The warnings the command line prints (the input's, then the course's), for the Python
    // side to raise as `FormationWarning`s.
    let mut warnings: Vec<String> = report
        .params
        .summary
        .as_ref()
        .map(|s| s.warnings.iter().map(|w| w.message.clone()).collect())
        .unwrap_or_default();
    warnings.extend(report.course.warnings.iter().cloned());
    Ok((
        PyAnimation {
            inner: anim,
            config,
        },
        warnings,
    ))
}

/// Reads an animation JSON file written by `formation animate`.
#[pyfunction]
fn read_animation(py: Python<'_>, path: PathBuf) -> PyResult<PyAnimation> {
    let inner = py.detach(|| Animation::read(&path)).map_err(py_err)?;
    Ok(PyAnimation {
        inner,
        config: Config::default(),
    })
}

/// Reads annotations from a file or directory with `read.` options (see
/// `formation.read_annotations`).
#[pyfunction]
fn read_annotations(
    py: Python<'_>,
    path: PathBuf,
    options: Vec<(String, String)>,
) -> PyResult<PyAnnotations> {
    let read: ReadOptions = merged(&ReadOptions::default(), &options, "read.")?;
    let inner = py
        .detach(|| annotations::read(&path, &read))
        .map_err(py_err)?;
    Ok(PyAnnotations { inner })
}

/// Annotations from points in memory: one (birds, 2) float64 array per frame, image pixels.
#[pyfunction]
fn annotations_from_points(
    source: String,
    heading: String,
    wingspan_px: f64,
    frames: Vec<PyReadonlyArray1<'_, f64>>,
) -> PyResult<PyAnnotations> {
    let heading: Heading = serde_json::from_str(&heading)
        .map_err(|e| PyValueError::new_err(format!("read.heading: {e}")))?;
    let frames: Vec<Vec<[f64; 2]>> = frames
        .iter()
        .map(|f| {
            f.as_slice()
                .map(|s| s.chunks_exact(2).map(|p| [p[0], p[1]]).collect())
        })
        .collect::<Result<_, _>>()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let inner = Annotations::from_points(&source, heading, wingspan_px, &frames).map_err(py_err)?;
    Ok(PyAnnotations { inner })
}

/// The parameter extraction only (see `formation.extract`).
#[pyfunction]
fn extract(
    py: Python<'_>,
    input: &Bound<'_, PyAny>,
    options: Vec<(String, String)>,
) -> PyResult<PyParams> {
    let pipeline = pipeline(input)?;
    let config = config(&options)?;
    let (inner, _) = py
        .detach(|| {
            config.extract.validate()?;
            pipeline.params(&config, &Silent)
        })
        .map_err(py_err)?;
    Ok(PyParams { inner })
}

/// What `power` returns: e and ξ per bird, and E.
type PowerOut<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, f64);

/// e, ξ and E of a shape (see `formation.power`): the planar wake, or with heights `z` and the
/// option `wake` = `3d` the 3-D one; the option `model` = `lissaman` for the lifting-line model.
#[pyfunction]
#[pyo3(signature = (x, y, z, options))]
fn power<'py>(
    py: Python<'py>,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Option<Vec<f64>>,
    options: Vec<(String, String)>,
) -> PyResult<PowerOut<'py>> {
    let aero = merged(&formation::aero::AeroOptions::default(), &options, "aero.")?;
    if x.len() != y.len() {
        return Err(PyValueError::new_err(format!(
            "y: {} values for {} birds in x",
            y.len(),
            x.len()
        )));
    }
    let pr = py
        .detach(|| match &z {
            Some(z) => aero.power_reduction_3d(&x, &y, z),
            // Without heights: planar, but with the model the options name.
            None => aero.power_reduction_3d(&x, &y, &vec![0.0; x.len()]),
        })
        .map_err(py_err)?;
    Ok((pr.e.into_pyarray(py), pr.xi.into_pyarray(py), pr.total))
}

/// Solves for the longitudinal positions giving target savings (see `formation.solve`).
#[pyfunction]
fn solve<'py>(
    py: Python<'py>,
    x: Vec<f64>,
    xi: Vec<f64>,
    y: Option<Vec<f64>>,
    tolerance: Option<f64>,
    patience: Option<usize>,
    aero: Vec<(String, String)>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let mut opts = formation::keyshape::solve::SolveOptions {
        aero: merged(&formation::aero::AeroOptions::default(), &aero, "aero.")?,
        ..Default::default()
    };
    if let Some(t) = tolerance {
        opts.tolerance = t;
    }
    if let Some(p) = patience {
        opts.patience = p;
    }
    let report = py
        .detach(|| {
            opts.validate()?;
            formation::keyshape::solve::solve(&x, &xi, y.as_deref(), &opts)
        })
        .map_err(py_err)?;
    let d = pyo3::types::PyDict::new(py);
    d.set_item("y", report.y.into_pyarray(py))?;
    d.set_item("xi", report.xi.into_pyarray(py))?;
    d.set_item("target", report.target.into_pyarray(py))?;
    d.set_item("residual", report.residual)?;
    d.set_item("converged", report.converged)?;
    d.set_item("total", report.total)?;
    d.set_item("evaluations", report.evaluations)?;
    d.set_item("termination", report.termination)?;
    Ok(d)
}

/// Runs the `formation` command line with `args` (without the program name) and returns its
/// exit status; what the wheel's `formation` command calls.
#[pyfunction]
fn run_cli(py: Python<'_>, args: Vec<String>) -> u8 {
    let argv: Vec<String> = std::iter::once("formation".to_string())
        .chain(args)
        .collect();
    let code = py.detach(|| cli_main::run_main(argv));
    use std::io::Write;
    let _ = std::io::stdout().flush();
    code
}

/// The default value of every option, as the JSON text of the library's configuration.
#[pyfunction]
fn default_options() -> PyResult<String> {
    serde_json::to_string(&Config::default()).map_err(|e| PyValueError::new_err(e.to_string()))
}

#[pymodule]
#[pyo3(name = "_native")]
fn formation_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAnimation>()?;
    m.add_class::<PyAnnotations>()?;
    m.add_class::<PyParams>()?;
    m.add_function(wrap_pyfunction!(animate, m)?)?;
    m.add_function(wrap_pyfunction!(read_animation, m)?)?;
    m.add_function(wrap_pyfunction!(read_annotations, m)?)?;
    m.add_function(wrap_pyfunction!(annotations_from_points, m)?)?;
    m.add_function(wrap_pyfunction!(extract, m)?)?;
    m.add_function(wrap_pyfunction!(power, m)?)?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(run_cli, m)?)?;
    m.add_function(wrap_pyfunction!(default_options, m)?)?;
    m.add_function(wrap_pyfunction!(from_state, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
