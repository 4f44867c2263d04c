//! The atlas file (SPEC §3.2): one HDF5 file per scene with the coordinates `alpha, beta,
//! kappa, energy, component` as HDF5 dimension scales attached to every variable (so that
//! xarray's h5netcdf engine shows named dimensions), CF-style attributes, and variables
//! chunked one (α, β) slice per chunk and compressed.

use crate::atlas::{Block, Column, Kind, Unit, Variable, COMPONENT_SLOTS, FLAG_FILL};
use crate::error::{AtlasError, Result};
use crate::scene::{Plane, Scene};
use hdf5::types::VarLenUnicode;
use ndarray::s;
use std::ffi::CString;
use std::path::{Path, PathBuf};

/// The HDF5 high-level library's dimension-scale calls (`hdf5_hl`, linked by build.rs; the
/// `hdf5` crate has no binding for them).
mod ds {
    use std::ffi::{c_char, c_int, c_uint, c_void};
    pub type Hid = i64;
    extern "C" {
        pub fn H5DSset_scale(dsid: Hid, dimname: *const c_char) -> c_int;
        pub fn H5DSattach_scale(did: Hid, dsid: Hid, idx: c_uint) -> c_int;
    }
    // HDF5 ≥ 1.10.2: write a chunk that is already filtered (here: shuffled and deflated).
    extern "C" {
        pub fn H5Dwrite_chunk(
            dset_id: Hid,
            dxpl_id: Hid,
            filters: u32,
            offset: *const u64,
            data_size: usize,
            buf: *const c_void,
        ) -> c_int;
    }
    /// H5P_DEFAULT.
    pub const DEFAULT: Hid = 0;
}

/// The deflate level of the variables (1: a third of level 4's time for 10–20 % more bytes
/// on these arrays after the shuffle filter).
const DEFLATE_LEVEL: u8 = 1;

/// The names of the dimensions, slowest first.
pub const DIMENSIONS: [&str; 5] = ["alpha", "beta", "kappa", "energy", "component"];

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
        Self::create_inner(path, scene, variables, attributes)
            .map_err(|e| AtlasError::atlas(path, e))
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
        let [row_name, column_name] = scene.plane.axis_names();
        let (row_long, column_long) = match scene.plane {
            Plane::KappaEnergy => (
                "kappa = F2, the first integral of the reduction",
                "energy, the value of the reduced energy integral",
            ),
            Plane::KappaExcess => (
                "kappa = F2, the first integral of the reduction",
                "excess energy: energy minus the bottom of V (its deepest minimum) at this kappa",
            ),
            Plane::Compact => (
                "lambda = kappa / sqrt(energy), fixed along the high-energy limit",
                "s = 1 / sqrt(energy): s = 0 is energy = infinity (the high-energy limit)",
            ),
        };
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
                row_name,
                &scene.kappa.values,
                row_long,
                "paper units (m = b3 = g = 1)",
            ),
            (
                column_name,
                &scene.energy.values,
                column_long,
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
        let rows = crate::atlas::rows_per_unit(shape);
        let mut datasets = Vec::with_capacity(variables.len());
        for v in variables {
            let per_cell = v.kind.per_cell();
            let d = if v.kind == Kind::CellValue {
                file.new_dataset::<f64>()
                    .chunk([1, 1, rows, ne])
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(f64::NAN)
                    .shape([na, nb, nk, ne])
                    .create(v.name)?
            } else if per_cell {
                // Where no unit was written (another shard's cells), `cell_status` reads
                // `not_computed`, never `ok`; `n_components` reads 0.
                let fill = if v.name == "cell_status" {
                    crate::atlas::cell_status::NOT_COMPUTED
                } else {
                    0u8
                };
                file.new_dataset::<u8>()
                    .chunk([1, 1, rows, ne])
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(fill)
                    .shape([na, nb, nk, ne])
                    .create(v.name)?
            } else if v.kind == Kind::Value {
                file.new_dataset::<f64>()
                    .chunk([1, 1, rows, ne, COMPONENT_SLOTS])
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(f64::NAN)
                    .shape([na, nb, nk, ne, COMPONENT_SLOTS])
                    .create(v.name)?
            } else {
                file.new_dataset::<u8>()
                    .chunk([1, 1, rows, ne, COMPONENT_SLOTS])
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(FLAG_FILL)
                    .shape([na, nb, nk, ne, COMPONENT_SLOTS])
                    .create(v.name)?
            };
            text_attr(&d, "long_name", v.long_name)?;
            text_attr(&d, "units", v.units)?;
            match v.kind {
                Kind::Value | Kind::CellValue => d
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
            // κ and ε per cell, where they are not axes: CF auxiliary coordinates of every
            // variable of the grid.
            let auxiliary = scene.plane.auxiliary();
            if !auxiliary.is_empty() && v.kind != Kind::CellValue {
                text_attr(&d, "coordinates", &auxiliary.join(" "))?;
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
        inner().map_err(|e| AtlasError::atlas(path, e))
    }

    /// Whether every variable has the grid's shape and reads to its last chunk (a damaged
    /// chunk fails its filter when read): an existing output taken as current must be whole.
    pub fn is_whole(&self) -> bool {
        self.variables.iter().zip(&self.datasets).all(|(v, d)| {
            let mut shape = self.shape.to_vec();
            if !v.kind.per_cell() {
                shape.push(COMPONENT_SLOTS);
            }
            d.shape() == shape
                && match v.kind {
                    Kind::Value | Kind::CellValue => d.read_raw::<f64>().is_ok(),
                    Kind::Flag | Kind::CellFlag => d.read_raw::<u8>().is_ok(),
                }
        })
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

    /// Writes a unit encoded by [`encode_unit`] (one chunk per variable) as HDF5 stores it.
    pub fn write_encoded(&self, unit: &Unit, encoded: &EncodedUnit) -> Result<()> {
        for ((v, d), bytes) in self
            .variables
            .iter()
            .zip(&self.datasets)
            .zip(&encoded.chunks)
        {
            let mut offset = vec![
                unit.alpha_index as u64,
                unit.beta_index as u64,
                unit.rows.start as u64,
                0,
            ];
            if !v.kind.per_cell() {
                offset.push(0);
            }
            let status = hdf5::sync::sync(|| unsafe {
                ds::H5Dwrite_chunk(
                    d.id(),
                    ds::DEFAULT,
                    0,
                    offset.as_ptr(),
                    bytes.len(),
                    bytes.as_ptr().cast(),
                )
            });
            if status < 0 {
                return Err(AtlasError::atlas(
                    &self.path,
                    format!("H5Dwrite_chunk failed for {}", v.name),
                ));
            }
        }
        Ok(())
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
                    Kind::CellValue => Column::F64(
                        d.read_slice::<f64, _, ndarray::Ix2>(s![ia, ib, r.clone(), ..])?
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
        read().map_err(|e| AtlasError::atlas(&self.path, e))
    }

    /// Flushes and closes the file, and flushes it to disk.
    pub fn close(self) -> Result<()> {
        let path = self.path.clone();
        drop(self.datasets);
        self.file.close().map_err(|e| AtlasError::atlas(&path, e))?;
        std::fs::File::open(&path)
            .and_then(|f| f.sync_all())
            .map_err(|e| AtlasError::atlas(&path, e))
    }
}

/// A work unit in the form HDF5 stores it: one shuffled, deflated chunk per variable.
pub struct EncodedUnit {
    chunks: Vec<Vec<u8>>,
}

impl EncodedUnit {
    /// The stored chunks, one per variable.
    pub fn chunks(&self) -> &[Vec<u8>] {
        &self.chunks
    }

    /// Chunks read back (from the resume journal).
    pub fn from_chunks(chunks: Vec<Vec<u8>>) -> Self {
        Self { chunks }
    }
}

/// Encodes `block`, the values of one unit of a grid of shape `shape`, chunk by chunk as
/// HDF5's shuffle and deflate filters would (a unit is one chunk of every variable). Done in
/// the worker threads: HDF5 runs its filters on the one thread that writes, which cost a
/// 2-thread run a third of its speed.
pub fn encode_unit(variables: &[Variable], block: &Block, shape: [usize; 4]) -> EncodedUnit {
    let chunk_cells = crate::atlas::rows_per_unit(shape) * shape[3];
    let chunks = variables
        .iter()
        .zip(&block.columns)
        .map(|(v, column)| {
            let width = if v.kind.per_cell() {
                1
            } else {
                COMPONENT_SLOTS
            };
            chunk_bytes(column, 0, block.cells * width, chunk_cells * width)
        })
        .collect();
    EncodedUnit { chunks }
}

/// The stored form of one chunk: values `from..to` of `column`, padded with the fill value to
/// `len` (an edge chunk is stored whole), byte-shuffled (HDF5's shuffle filter: byte k of
/// every element together) and deflated (zlib stream, as HDF5's deflate filter).
fn chunk_bytes(column: &Column, from: usize, to: usize, len: usize) -> Vec<u8> {
    use std::io::Write;
    let shuffled = match column {
        Column::U8(x) => {
            let mut raw = x[from..to].to_vec();
            raw.resize(len, FLAG_FILL);
            raw
        }
        Column::F64(x) => {
            let values = &x[from..to];
            let mut raw = vec![0u8; 8 * len];
            let nan = f64::NAN.to_le_bytes();
            for i in 0..len {
                let b = values.get(i).map_or(nan, |v| v.to_le_bytes());
                for (k, byte) in b.into_iter().enumerate() {
                    raw[k * len + i] = byte;
                }
            }
            raw
        }
    };
    let mut encoder = flate2::write::ZlibEncoder::new(
        Vec::with_capacity(shuffled.len() / 4),
        flate2::Compression::new(u32::from(DEFLATE_LEVEL)),
    );
    encoder.write_all(&shuffled).expect("writing to memory");
    encoder.finish().expect("writing to memory")
}
