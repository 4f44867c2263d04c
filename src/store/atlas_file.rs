//! The atlas file (SPEC §3.2): one HDF5 file per scene with the coordinates `alpha, beta,
//! kappa, energy, component` as HDF5 dimension scales attached to every variable (so that
//! xarray's h5netcdf engine shows named dimensions), CF-style attributes, and variables
//! chunked one (α, β) slice per chunk and compressed.

use crate::atlas::{Block, Column, Kind, Unit, Variable, COMPONENT_SLOTS, FLAG_FILL};
use crate::error::{AtlasError, Result};
use crate::scene::Scene;
use hdf5::types::VarLenUnicode;
use ndarray::{s, ArrayView2, ArrayView3};
use std::ffi::CString;
use std::path::{Path, PathBuf};

/// The HDF5 high-level library's dimension-scale calls (`hdf5_hl`, linked by build.rs; the
/// `hdf5` crate has no binding for them).
mod ds {
    use std::ffi::{c_char, c_int, c_uint};
    pub type Hid = i64;
    extern "C" {
        pub fn H5DSset_scale(dsid: Hid, dimname: *const c_char) -> c_int;
        pub fn H5DSattach_scale(did: Hid, dsid: Hid, idx: c_uint) -> c_int;
    }
}

/// The names of the dimensions, slowest first.
pub const DIMENSIONS: [&str; 5] = ["alpha", "beta", "kappa", "energy", "component"];

/// The largest chunk, in bytes: a (κ, ε) slice is one chunk unless it is larger than this,
/// then it is split along κ.
const CHUNK_BYTES: usize = 16 << 20;

/// A root attribute value.
#[derive(Debug, Clone, PartialEq)]
pub enum AttrValue {
    Text(String),
    Number(f64),
    Integer(i64),
}

/// An open atlas file.
pub struct AtlasFile {
    path: PathBuf,
    file: hdf5::File,
    datasets: Vec<hdf5::Dataset>,
    variables: Vec<Variable>,
    shape: [usize; 4],
}

fn h5_error(path: &Path, e: impl std::fmt::Display) -> AtlasError {
    AtlasError::Atlas {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

fn text_attr(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    let v: VarLenUnicode = value
        .parse()
        .map_err(|e: hdf5::types::StringError| hdf5::Error::from(e.to_string().as_str()))?;
    loc.new_attr::<VarLenUnicode>()
        .create(name)?
        .write_scalar(&v)
}

fn write_attr(loc: &hdf5::Location, name: &str, value: &AttrValue) -> hdf5::Result<()> {
    match value {
        AttrValue::Text(t) => text_attr(loc, name, t),
        AttrValue::Number(x) => loc.new_attr::<f64>().create(name)?.write_scalar(x),
        AttrValue::Integer(i) => loc.new_attr::<i64>().create(name)?.write_scalar(i),
    }
}

fn set_scale(dataset: &hdf5::Dataset, name: &str) -> hdf5::Result<()> {
    let name = CString::new(name).expect("dimension names have no NUL");
    let status = hdf5::sync::sync(|| unsafe { ds::H5DSset_scale(dataset.id(), name.as_ptr()) });
    if status < 0 {
        return Err(format!("H5DSset_scale failed for {name:?}").as_str().into());
    }
    Ok(())
}

fn attach_scale(dataset: &hdf5::Dataset, scale: &hdf5::Dataset, index: usize) -> hdf5::Result<()> {
    let status = hdf5::sync::sync(|| unsafe {
        ds::H5DSattach_scale(dataset.id(), scale.id(), index as std::ffi::c_uint)
    });
    if status < 0 {
        return Err("H5DSattach_scale failed".into());
    }
    Ok(())
}

impl AtlasFile {
    /// Creates the file at `path` (which must not exist) with the scene's coordinates, every
    /// variable at its fill value, and `attributes` on the root.
    pub fn create(
        path: &Path,
        scene: &Scene,
        variables: &[Variable],
        attributes: &[(&str, AttrValue)],
    ) -> Result<AtlasFile> {
        Self::create_inner(path, scene, variables, attributes).map_err(|e| h5_error(path, e))
    }

    fn create_inner(
        path: &Path,
        scene: &Scene,
        variables: &[Variable],
        attributes: &[(&str, AttrValue)],
    ) -> hdf5::Result<AtlasFile> {
        let file = hdf5::File::create_excl(path)?;
        text_attr(&file, "Conventions", "CF-1.8")?;
        for (name, value) in attributes {
            write_attr(&file, name, value)?;
        }
        let coords: [(&str, &[f64], &str, &str); 4] = [
            (
                "alpha",
                &scene.alpha.values,
                "alpha = a / b3, offset of the centre of mass along the symmetry axis",
                "1",
            ),
            (
                "beta",
                &scene.beta.values,
                "beta = b1 / b3, ratio of the semi-axes",
                "1",
            ),
            (
                "kappa",
                &scene.kappa.values,
                "kappa = F2, the first integral of the reduction",
                "paper units (m = b3 = g = 1)",
            ),
            (
                "energy",
                &scene.energy.values,
                "energy, the value of the reduced energy integral",
                "paper units (m = b3 = g = 1)",
            ),
        ];
        let mut scales = Vec::new();
        for (name, values, long_name, units) in coords {
            let d = file.new_dataset_builder().with_data(values).create(name)?;
            text_attr(&d, "long_name", long_name)?;
            text_attr(&d, "units", units)?;
            set_scale(&d, name)?;
            scales.push(d);
        }
        let slots: Vec<i32> = (0..COMPONENT_SLOTS as i32).collect();
        let d = file
            .new_dataset_builder()
            .with_data(&slots)
            .create("component")?;
        text_attr(
            &d,
            "long_name",
            "component of the allowed set, in increasing theta_min",
        )?;
        text_attr(&d, "units", "1")?;
        set_scale(&d, "component")?;
        scales.push(d);

        let shape = scene.shape();
        let [na, nb, nk, ne] = shape;
        let mut datasets = Vec::with_capacity(variables.len());
        for v in variables {
            let per_cell = v.kind == Kind::CellFlag;
            let width = if per_cell { 1 } else { COMPONENT_SLOTS };
            let item = if v.kind == Kind::Value { 8 } else { 1 };
            let rows = (CHUNK_BYTES / (ne * width * item).max(1)).clamp(1, nk);
            let d = if per_cell {
                file.new_dataset::<u8>()
                    .chunk([1, 1, rows, ne])
                    .shuffle()
                    .deflate(4)
                    .fill_value(0u8)
                    .shape([na, nb, nk, ne])
                    .create(v.name)?
            } else if v.kind == Kind::Value {
                file.new_dataset::<f64>()
                    .chunk([1, 1, rows, ne, COMPONENT_SLOTS])
                    .shuffle()
                    .deflate(4)
                    .fill_value(f64::NAN)
                    .shape([na, nb, nk, ne, COMPONENT_SLOTS])
                    .create(v.name)?
            } else {
                file.new_dataset::<u8>()
                    .chunk([1, 1, rows, ne, COMPONENT_SLOTS])
                    .shuffle()
                    .deflate(4)
                    .fill_value(FLAG_FILL)
                    .shape([na, nb, nk, ne, COMPONENT_SLOTS])
                    .create(v.name)?
            };
            text_attr(&d, "long_name", v.long_name)?;
            text_attr(&d, "units", v.units)?;
            match v.kind {
                Kind::Value => d
                    .new_attr::<f64>()
                    .create("_FillValue")?
                    .write_scalar(&f64::NAN)?,
                Kind::Flag => d
                    .new_attr::<u8>()
                    .create("_FillValue")?
                    .write_scalar(&FLAG_FILL)?,
                Kind::CellFlag => {}
            }
            if let Some((values, meanings)) = v.flags {
                d.new_attr::<u8>()
                    .shape(values.len())
                    .create("flag_values")?
                    .write_raw(values)?;
                text_attr(&d, "flag_meanings", meanings)?;
            }
            let dims = if per_cell { 4 } else { 5 };
            for (i, scale) in scales.iter().take(dims).enumerate() {
                attach_scale(&d, scale, i)?;
            }
            datasets.push(d);
        }
        Ok(AtlasFile {
            path: path.to_path_buf(),
            file,
            datasets,
            variables: variables.to_vec(),
            shape,
        })
    }

    /// Opens an existing atlas file for reading; `variables` are those its scene asks for.
    pub fn open(path: &Path, scene: &Scene, variables: &[Variable]) -> Result<AtlasFile> {
        let inner = || -> hdf5::Result<AtlasFile> {
            let file = hdf5::File::open(path)?;
            let datasets = variables
                .iter()
                .map(|v| file.dataset(v.name))
                .collect::<hdf5::Result<Vec<_>>>()?;
            Ok(AtlasFile {
                path: path.to_path_buf(),
                file,
                datasets,
                variables: variables.to_vec(),
                shape: scene.shape(),
            })
        };
        inner().map_err(|e| h5_error(path, e))
    }

    /// A text attribute of the root, if present.
    pub fn text_attribute(&self, name: &str) -> Option<String> {
        self.file
            .attr(name)
            .and_then(|a| a.read_scalar::<VarLenUnicode>())
            .ok()
            .map(|s| s.as_str().to_string())
    }

    /// An integer attribute of the root, if present.
    pub fn integer_attribute(&self, name: &str) -> Option<i64> {
        self.file
            .attr(name)
            .and_then(|a| a.read_scalar::<i64>())
            .ok()
    }

    /// Writes the values of `unit`.
    pub fn write_unit(&self, unit: &Unit, block: &Block) -> Result<()> {
        let ne = self.shape[3];
        let rows = unit.rows.len();
        let (ia, ib, r) = (unit.alpha_index, unit.beta_index, unit.rows.clone());
        let write = || -> hdf5::Result<()> {
            for ((v, d), column) in self
                .variables
                .iter()
                .zip(&self.datasets)
                .zip(&block.columns)
            {
                match (v.kind, column) {
                    (Kind::CellFlag, Column::U8(x)) => {
                        let view = ArrayView2::from_shape((rows, ne), x).map_err(shape_error)?;
                        d.write_slice(view, s![ia, ib, r.clone(), ..])?
                    }
                    (Kind::Flag, Column::U8(x)) => {
                        let view = ArrayView3::from_shape((rows, ne, COMPONENT_SLOTS), x)
                            .map_err(shape_error)?;
                        d.write_slice(view, s![ia, ib, r.clone(), .., ..])?
                    }
                    (Kind::Value, Column::F64(x)) => {
                        let view = ArrayView3::from_shape((rows, ne, COMPONENT_SLOTS), x)
                            .map_err(shape_error)?;
                        d.write_slice(view, s![ia, ib, r.clone(), .., ..])?
                    }
                    _ => return Err("a block's column does not match its variable".into()),
                }
            }
            Ok(())
        };
        write().map_err(|e| h5_error(&self.path, e))
    }

    /// Reads the values of `unit`.
    pub fn read_unit(&self, unit: &Unit) -> Result<Block> {
        let (ia, ib, r) = (unit.alpha_index, unit.beta_index, unit.rows.clone());
        let read = || -> hdf5::Result<Block> {
            let mut columns = Vec::with_capacity(self.variables.len());
            for (v, d) in self.variables.iter().zip(&self.datasets) {
                columns.push(match v.kind {
                    Kind::CellFlag => Column::U8(
                        d.read_slice::<u8, _, ndarray::Ix2>(s![ia, ib, r.clone(), ..])?
                            .into_raw_vec_and_offset()
                            .0,
                    ),
                    Kind::Flag => Column::U8(
                        d.read_slice::<u8, _, ndarray::Ix3>(s![ia, ib, r.clone(), .., ..])?
                            .into_raw_vec_and_offset()
                            .0,
                    ),
                    Kind::Value => Column::F64(
                        d.read_slice::<f64, _, ndarray::Ix3>(s![ia, ib, r.clone(), .., ..])?
                            .into_raw_vec_and_offset()
                            .0,
                    ),
                });
            }
            Ok(Block {
                cells: unit.rows.len() * self.shape[3],
                columns,
            })
        };
        read().map_err(|e| h5_error(&self.path, e))
    }

    /// Flushes and closes the file, and flushes it to disk.
    pub fn close(self) -> Result<()> {
        let path = self.path.clone();
        drop(self.datasets);
        self.file.close().map_err(|e| h5_error(&path, e))?;
        std::fs::File::open(&path)
            .and_then(|f| f.sync_all())
            .map_err(|e| h5_error(&path, e))
    }
}

fn shape_error(e: ndarray::ShapeError) -> hdf5::Error {
    e.to_string().as_str().into()
}
