//! The atlas file (docs/files.md): one HDF5 file per scene with the coordinates (the shape's
//! parameters: `alpha, beta` of the ellipsoid, `alpha, cut` of the cut balls, `alpha` of the
//! disk; the plane's two; `component`) as HDF5 dimension scales attached to every variable (so
//! that xarray's h5netcdf engine shows named dimensions), CF attributes, and variables chunked
//! one work unit (whole κ-rows of one body's slice) per chunk and compressed. A file holds a
//! region of the scene's grid: all of it, or a shard's box.

use super::h5::{attach_scale, describe, set_scale, text_attr, write_attr};
use crate::atlas::{Block, Column, Kind, Region, Unit, Variable, FLAG_FILL};
use crate::cf;
use crate::error::{AtlasError, Result};
use crate::family::ComponentAxis;
use crate::scene::{Plane, Scene};
use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};

/// The deflate level of the variables (1: a third of level 4's time for 10–20 % more bytes
/// on these arrays after the shuffle filter).
const DEFLATE_LEVEL: u8 = 1;

/// The names of an ellipsoid atlas's dimensions on the (κ, ε) plane, slowest first.
pub const DIMENSIONS: [&str; 5] = ["alpha", "beta", "kappa", "energy", "component"];

pub use crate::cf::AttrValue;

/// An open atlas file.
pub struct AtlasFile {
    path: PathBuf,
    file: hdf5::File,
    datasets: Vec<hdf5::Dataset>,
    variables: Vec<Variable>,
    region: Region,
    axis: ComponentAxis,
    /// Whether the file has the grid's second dimension (every shape but the disk).
    second: bool,
}

/// The root attribute holding [`super::h5::text_attributes_crc32`] of the file as written.
pub const TEXT_CRC: &str = "text_attributes_crc32";

impl AtlasFile {
    /// Creates the file at `path` (which must not exist) for the part `region` of the
    /// scene's grid (all of it, or a shard's), with its coordinates, every variable at its
    /// fill value, and `attributes` on the root.
    pub fn create(
        path: &Path,
        scene: &Scene,
        region: &Region,
        variables: &[Variable],
        axis: &ComponentAxis,
        attributes: &[(&str, AttrValue)],
    ) -> Result<AtlasFile> {
        Self::create_inner(path, scene, region, variables, axis, attributes)
            .map_err(|e| AtlasError::atlas(path, e))
    }

    fn create_inner(
        path: &Path,
        scene: &Scene,
        region: &Region,
        variables: &[Variable],
        axis: &ComponentAxis,
        attributes: &[(&str, AttrValue)],
    ) -> hdf5::Result<AtlasFile> {
        // HDF5 1.10's formats: every header, B-tree and chunk index carries a checksum, so a
        // flipped bit in the file's structure or attributes is refused when read, not taken
        // (the chunks' zlib streams carry their own).
        let file = hdf5::File::with_options()
            .with_fapl(|p| {
                p.libver_bounds(
                    hdf5::file::LibraryVersion::V110,
                    hdf5::file::LibraryVersion::latest(),
                )
            })
            .create_excl(path)?;
        text_attr(&file, "Conventions", cf::CONVENTIONS)?;
        text_attr(&file, "component_layout", axis.layout.name())?;
        for (name, value) in attributes {
            write_attr(&file, name, value)?;
        }
        let [row_name, column_name] = scene.plane.axis_names();
        let known = |name: &str| crate::atlas::coordinate(name).expect("a coordinate's name");
        let (row, column) = match scene.plane {
            Plane::KappaEnergy => (known("kappa"), known("energy")),
            Plane::KappaExcess => (
                known("kappa"),
                (
                    "excess energy: energy minus the bottom of V (its deepest minimum) at this kappa",
                    cf::ENERGY,
                ),
            ),
            Plane::Compact => (
                (
                    "lambda = kappa / sqrt(energy), fixed along the high-energy limit",
                    cf::PAPER,
                ),
                (
                    "s = 1 / sqrt(energy): s = 0 is energy = infinity (the high-energy limit)",
                    cf::PAPER,
                ),
            ),
        };
        let second = scene
            .second_name()
            .map(|name| (name, &scene.second.values[region.beta.clone()], known(name)));
        let coords: Vec<(&str, &[f64], (&str, cf::Units))> = [(
            "alpha",
            &scene.alpha.values[region.alpha.clone()],
            known("alpha"),
        )]
        .into_iter()
        .chain(second)
        .chain([
            (row_name, &scene.kappa.values[region.rows.clone()], row),
            (column_name, &scene.energy.values[..], column),
        ])
        .collect();
        let mut scales = Vec::new();
        for (name, values, (long_name, units)) in coords {
            // Chunked, for the Fletcher-32 checksum of the values (a contiguous dataset has
            // none: a flipped bit in κ would read as another grid).
            let d = file
                .new_dataset_builder()
                .chunk(values.len())
                .fletcher32()
                .with_data(values)
                .create(name)?;
            describe(&d, long_name, units)?;
            set_scale(&d, name)?;
            scales.push(d);
        }
        // The body's mass parameters: scalar coordinates of every variable.
        for (name, value) in [("nu", scene.nu), ("eta", scene.eta)] {
            let d = file.new_dataset::<f64>().create(name)?;
            d.write_scalar(&value)?;
            let (long_name, units) = known(name);
            describe(&d, long_name, units)?;
        }
        // By family: the families' codes (u8 flags); by θ_min: the ranks 0, 1, … (int32).
        let slots_len = axis.len();
        let d = match axis.flag_attributes() {
            Some((values, meanings)) => {
                let d = file
                    .new_dataset_builder()
                    .chunk(slots_len)
                    .fletcher32()
                    .with_data(&axis.labels)
                    .create("component")?;
                describe(&d, "torus family", cf::NUMBER)?;
                super::h5::flags(&d, (&values, &meanings))?;
                d
            }
            None => {
                let ranks: Vec<i32> = axis.labels.iter().map(|&k| i32::from(k)).collect();
                let d = file
                    .new_dataset_builder()
                    .chunk(slots_len)
                    .fletcher32()
                    .with_data(&ranks)
                    .create("component")?;
                describe(
                    &d,
                    "rank of the component in increasing theta_min",
                    cf::NUMBER,
                )?;
                d
            }
        };
        set_scale(&d, "component")?;
        scales.push(d);
        let slots = axis.len();

        let has_second = scene.second_name().is_some();
        let [na, nb, nk, ne] = region.shape();
        let [betas, rows] = region.chunk(scene.shape());
        // The dimensions of a variable per cell, and of one per cell and component.
        let (cell_shape, cell_chunk) = if has_second {
            (vec![na, nb, nk, ne], vec![1, betas, rows, ne])
        } else {
            (vec![na, nk, ne], vec![1, rows, ne])
        };
        let with_slots = |dims: &[usize], n: usize| [dims, &[n]].concat();
        let (slot_shape, slot_chunk) = (
            with_slots(&cell_shape, slots),
            with_slots(&cell_chunk, slots),
        );
        let mut datasets = Vec::with_capacity(variables.len());
        for v in variables {
            let per_cell = v.kind.per_cell();
            let d = if v.kind == Kind::CellValue {
                file.new_dataset::<f64>()
                    .chunk(cell_chunk.clone())
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(f64::NAN)
                    .shape(cell_shape.clone())
                    .create(v.name)?
            } else if per_cell {
                // Where no unit was written yet, `cell_status` reads `not_computed`, never
                // `ok`; `n_components` reads 0.
                let fill = if v.name == "cell_status" {
                    crate::atlas::cell_status::NOT_COMPUTED
                } else {
                    0u8
                };
                file.new_dataset::<u8>()
                    .chunk(cell_chunk.clone())
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(fill)
                    .shape(cell_shape.clone())
                    .create(v.name)?
            } else if v.kind == Kind::Value {
                file.new_dataset::<f64>()
                    .chunk(slot_chunk.clone())
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(f64::NAN)
                    .shape(slot_shape.clone())
                    .create(v.name)?
            } else {
                file.new_dataset::<u8>()
                    .chunk(slot_chunk.clone())
                    .shuffle()
                    .deflate(DEFLATE_LEVEL)
                    .fill_value(FLAG_FILL)
                    .shape(slot_shape.clone())
                    .create(v.name)?
            };
            describe(&d, v.long_name, v.units)?;
            // Floats are NaN where a component does not exist. Flags take FLAG_FILL there,
            // a value of their own (`flag_values`, `flag_meanings`), not a _FillValue: a
            // _FillValue would make xarray decode them as floats with NaN.
            if matches!(v.kind, Kind::Value | Kind::CellValue) {
                d.new_attr::<f64>()
                    .create("_FillValue")?
                    .write_scalar(&f64::NAN)?;
            }
            if let Some((values, meanings)) = v.flag_attributes() {
                super::h5::flags(&d, (&values, &meanings))?;
            }
            // ν and η, and κ and ε per cell where they are not axes (CF auxiliary
            // coordinates).
            let mut coordinates = vec!["nu", "eta"];
            if v.kind != Kind::CellValue {
                coordinates.extend(scene.plane.auxiliary());
            }
            text_attr(&d, "coordinates", &coordinates.join(" "))?;
            // The grid's scales, and the component's last where the variable has it.
            let grid = scales.len() - 1;
            let own: Vec<&hdf5::Dataset> = if per_cell {
                scales[..grid].iter().collect()
            } else {
                scales.iter().collect()
            };
            for (i, scale) in own.into_iter().enumerate() {
                attach_scale(&d, scale, i)?;
            }
            datasets.push(d);
        }
        // Last: it covers every text attribute written above.
        let crc = super::h5::text_attributes_crc32(&file)?;
        file.new_attr::<i64>()
            .create(TEXT_CRC)?
            .write_scalar(&i64::from(crc))?;
        Ok(AtlasFile {
            path: path.to_path_buf(),
            file,
            datasets,
            variables: variables.to_vec(),
            region: region.clone(),
            axis: axis.clone(),
            second: has_second,
        })
    }

    /// Opens an existing atlas file of the part `region` of `scene`'s grid for reading;
    /// `variables` are those its scene asks for, `axis` its component axis.
    pub fn open(
        path: &Path,
        scene: &Scene,
        region: &Region,
        variables: &[Variable],
        axis: &ComponentAxis,
    ) -> Result<AtlasFile> {
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
                region: region.clone(),
                axis: axis.clone(),
                second: scene.second_name().is_some(),
            })
        };
        inner().map_err(|e| AtlasError::atlas(path, e))
    }

    /// Whether the file at `path` is not an atlas of this program: not HDF5 at all (its
    /// signature is not at offset 0, where this program writes it), or HDF5 that opens and
    /// lacks what every atlas has: the root attributes `program` = "rubber-atlas" and `scene`,
    /// and the variable `cell_status` (another program's file, or a table of this one, such
    /// as `diagram --out`). A damaged atlas keeps those or fails to open: it is not foreign,
    /// and `--update` remakes it.
    pub fn is_foreign(path: &Path) -> bool {
        use std::io::Read;
        const SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";
        let mut start = [0u8; 8];
        let signed = std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut start))
            .is_ok_and(|()| &start == SIGNATURE);
        if !signed {
            return true;
        }
        hdf5::File::open(path).is_ok_and(|file| {
            let ours = file
                .attr("program")
                .and_then(|a| a.read_scalar::<VarLenUnicode>())
                .is_ok_and(|name| name.as_str() == "rubber-atlas");
            !(ours && file.attr("scene").is_ok() && file.dataset("cell_status").is_ok())
        })
    }

    /// Whether another process holds the file at `path` open for writing with HDF5's lock (an
    /// exclusive flock, which HDF5 takes on every file it opens to write: h5py in mode "a",
    /// another program writing it). Such a file cannot be opened here, which is neither
    /// damage nor proof that it is an atlas: `--update` must not replace it.
    pub fn is_locked_by_another(path: &Path) -> bool {
        std::fs::File::open(path)
            .is_ok_and(|f| matches!(f.try_lock_shared(), Err(std::fs::TryLockError::WouldBlock)))
    }

    /// The `scene_name` attribute of the atlas at `path`, if it can be read.
    pub fn scene_name(path: &Path) -> Option<String> {
        let file = hdf5::File::open(path).ok()?;
        let name = file.attr("scene_name").ok()?;
        Some(
            name.read_scalar::<VarLenUnicode>()
                .ok()?
                .as_str()
                .to_string(),
        )
    }

    /// The component axis an atlas file at `path` was written with (its `component_layout`
    /// and `component` coordinate).
    pub fn read_axis(path: &Path) -> Result<ComponentAxis> {
        let inner = || -> hdf5::Result<ComponentAxis> {
            let file = hdf5::File::open(path)?;
            let layout = file
                .attr("component_layout")
                .and_then(|a| a.read_scalar::<VarLenUnicode>())
                .ok()
                .and_then(|name| crate::family::Layout::from_name(name.as_str()))
                .ok_or("has no component_layout attribute of a known layout (made by an older version?)")?;
            let labels = file.dataset("component")?.read_raw::<i64>()?;
            let labels = labels
                .into_iter()
                .map(|k| u8::try_from(k).map_err(|_| "a component label beyond 255"))
                .collect::<std::result::Result<Vec<u8>, _>>()?;
            Ok(ComponentAxis { layout, labels })
        };
        inner().map_err(|e| AtlasError::atlas(path, e))
    }

    /// Whether every variable has the grid's shape and reads to its last chunk (a damaged
    /// chunk fails its filter when read): an existing output taken as current must be whole.
    pub fn is_whole(&self) -> bool {
        self.variables.iter().zip(&self.datasets).all(|(v, d)| {
            let mut shape = self.region.shape().to_vec();
            if !self.second {
                shape.remove(1);
            }
            if !v.kind.per_cell() {
                shape.push(self.axis.len());
            }
            d.shape() == shape
                && match v.kind {
                    Kind::Value | Kind::CellValue => d.read_raw::<f64>().is_ok(),
                    Kind::Flag | Kind::CellFlag => d.read_raw::<u8>().is_ok(),
                }
        })
    }

    /// Whether the file is the one a run of `scene` writes, whole: every variable reads
    /// ([`Self::is_whole`]), the coordinates and ν, η are the scene's value for value
    /// ([`Self::coordinates_match`]), every variable's dimensions are attached to their
    /// scales, and every attribute of the root and of every dataset opens and reads (the
    /// HDF5 1.10 headers' checksums refuse a flipped bit there), and the text attributes'
    /// letters, kept in HDF5's global heap without a checksum, have the CRC-32 the file was
    /// written with (`text_attributes_crc32`). Reading a damaged file can crash HDF5: ask
    /// this in a child process ([`crate::sweep::output_is_current`]).
    pub fn is_intact(&self, scene: &Scene) -> bool {
        self.is_whole()
            && self.coordinates_match(scene)
            && self.constants_match(scene)
            && self.scales_attached(scene)
            && self.texts_intact()
            && super::h5::objects(&self.file).is_ok_and(|objects| {
                objects
                    .iter()
                    .all(|(_, location)| super::h5::attributes_read(location))
            })
    }

    /// Whether the scalar variables ν and η are the scene's, bit for bit.
    pub fn constants_match(&self, scene: &Scene) -> bool {
        let scalar = |name: &str, want: f64| {
            self.file
                .dataset(name)
                .and_then(|d| d.read_scalar::<f64>())
                .is_ok_and(|got| got.to_bits() == want.to_bits())
        };
        scalar("nu", scene.nu) && scalar("eta", scene.eta)
    }

    /// Whether the text attributes' letters (kept in HDF5's global heap without a checksum)
    /// have the CRC-32 the file was written with (`text_attributes_crc32`).
    pub fn texts_intact(&self) -> bool {
        super::h5::text_attributes_crc32(&self.file)
            .is_ok_and(|crc| self.integer_attribute(TEXT_CRC) == Some(i64::from(crc)))
    }

    /// The grid's coordinates of this file's region of `scene`, by name, in the order of the
    /// variables' dimensions (before `component`).
    fn grid_coordinates<'s>(&self, scene: &'s Scene) -> Vec<(&'s str, &'s [f64])> {
        let r = &self.region;
        let [row, column] = scene.plane.axis_names();
        let second = scene
            .second_name()
            .map(|name| (name, &scene.second.values[r.beta.clone()]));
        [("alpha", &scene.alpha.values[r.alpha.clone()])]
            .into_iter()
            .chain(second)
            .chain([
                (row, &scene.kappa.values[r.rows.clone()]),
                (column, &scene.energy.values[..]),
            ])
            .collect()
    }

    /// Whether each variable's dimensions carry their coordinates as dimension scales.
    fn scales_attached(&self, scene: &Scene) -> bool {
        let Ok(grid) = self
            .grid_coordinates(scene)
            .iter()
            .map(|(name, _)| self.file.dataset(name))
            .collect::<hdf5::Result<Vec<_>>>()
        else {
            return false;
        };
        let Ok(component) = self.file.dataset("component") else {
            return false;
        };
        self.variables.iter().zip(&self.datasets).all(|(v, d)| {
            let own = grid
                .iter()
                .chain((!v.kind.per_cell()).then_some(&component));
            own.enumerate()
                .all(|(i, scale)| super::h5::is_attached(d, scale, i))
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

    /// Whether the file's coordinates are those of its region of `scene`'s grid, value for
    /// value, and its component axis the one it was opened with: a shard file relabelled by
    /// hand (its shard attributes edited) is caught here.
    pub fn coordinates_match(&self, scene: &Scene) -> bool {
        let layout = self.text_attribute("component_layout");
        let labels = self
            .file
            .dataset("component")
            .and_then(|d| d.read_raw::<i64>())
            .ok();
        let want: Vec<i64> = self.axis.labels.iter().map(|&k| i64::from(k)).collect();
        if layout.as_deref() != Some(self.axis.layout.name()) || labels != Some(want) {
            return false;
        }
        let expected = self.grid_coordinates(scene);
        expected.iter().all(|(name, want)| {
            self.file
                .dataset(name)
                .and_then(|d| d.read_raw::<f64>())
                .is_ok_and(|got| {
                    got.len() == want.len()
                        && got
                            .iter()
                            .zip(*want)
                            .all(|(a, b)| a.to_bits() == b.to_bits())
                })
        })
    }

    /// Writes a unit encoded by [`encode_unit`] (one chunk per variable) as HDF5 stores it.
    pub fn write_encoded(&self, unit: &Unit, encoded: &EncodedUnit) -> Result<()> {
        for ((v, d), bytes) in self
            .variables
            .iter()
            .zip(&self.datasets)
            .zip(&encoded.chunks)
        {
            let offset: Vec<u64> = self
                .unit_box(unit, v.kind)
                .iter()
                .map(|r| r.start as u64)
                .collect();
            // (errno cleared first: a failure without a system call must not show an
            // earlier call's errno.)
            // SAFETY: errno is this thread's own.
            unsafe { *libc::__errno_location() = 0 };
            let status = hdf5::sync::sync(|| unsafe {
                hdf5_sys::h5d::H5Dwrite_chunk(
                    d.id(),
                    hdf5_sys::h5p::H5P_DEFAULT,
                    0,
                    offset.as_ptr(),
                    bytes.len(),
                    bytes.as_ptr().cast(),
                )
            });
            if status < 0 {
                // (HDF5's file driver leaves the system's errno of the failed write: a full
                // disk said only "H5Dwrite_chunk failed".)
                let system = std::io::Error::last_os_error();
                let reason = match system.raw_os_error() {
                    Some(code) if code != 0 => format!(": {system}"),
                    _ => String::new(),
                };
                return Err(AtlasError::write_failed(
                    &self.path,
                    format!("writing {} failed{reason}", v.name),
                ));
            }
        }
        Ok(())
    }

    /// The box of `unit` in a variable of `kind` of this file, dimension by dimension.
    fn unit_box(&self, unit: &Unit, kind: Kind) -> Vec<std::ops::Range<usize>> {
        let g = &self.region;
        let ia = unit.alpha_index - g.alpha.start;
        let mut dims = Vec::with_capacity(5);
        dims.push(ia..ia + 1);
        if self.second {
            dims.push(unit.betas.start - g.beta.start..unit.betas.end - g.beta.start);
        }
        dims.push(unit.rows.start - g.rows.start..unit.rows.end - g.rows.start);
        dims.push(0..g.columns);
        if !kind.per_cell() {
            dims.push(0..self.axis.len());
        }
        dims
    }

    /// Reads the values of `unit`.
    pub fn read_unit(&self, unit: &Unit) -> Result<Block> {
        use hdf5::{Hyperslab, Selection, SliceOrIndex};
        let read = || -> hdf5::Result<Block> {
            let mut columns = Vec::with_capacity(self.variables.len());
            for (v, d) in self.variables.iter().zip(&self.datasets) {
                let slab: Vec<SliceOrIndex> = self
                    .unit_box(unit, v.kind)
                    .into_iter()
                    .map(|r| SliceOrIndex::SliceCount {
                        start: r.start,
                        step: 1,
                        count: r.len(),
                        block: 1,
                    })
                    .collect();
                let selection = Selection::from(Hyperslab::from(slab));
                columns.push(match v.kind {
                    Kind::CellFlag | Kind::Flag => Column::U8(
                        d.read_slice::<u8, _, ndarray::IxDyn>(selection)?
                            .into_raw_vec_and_offset()
                            .0,
                    ),
                    Kind::Value | Kind::CellValue => Column::F64(
                        d.read_slice::<f64, _, ndarray::IxDyn>(selection)?
                            .into_raw_vec_and_offset()
                            .0,
                    ),
                });
            }
            Ok(Block {
                cells: unit.cells(self.region.columns),
                slots: self.axis.len(),
                columns,
            })
        };
        read().map_err(|e| AtlasError::atlas(&self.path, e))
    }

    /// Flushes and closes the file, and flushes it to disk.
    pub fn close(self) -> Result<()> {
        let path = self.path.clone();
        drop(self.datasets);
        self.file
            .close()
            .map_err(|e| AtlasError::write_failed(&path, e))?;
        std::fs::File::open(&path)
            .and_then(|f| f.sync_all())
            .map_err(|e| AtlasError::write_failed(&path, e))
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

/// Encodes `block`, the values of one unit, as chunks of `chunk_cells` cells
/// ([`Region::chunk_cells`]), as HDF5's shuffle and deflate filters would (a unit is one
/// chunk of every variable). Done in
/// the worker threads: HDF5 runs its filters on the one thread that writes, which cost a
/// 2-thread run a third of its speed.
pub fn encode_unit(variables: &[Variable], block: &Block, chunk_cells: usize) -> EncodedUnit {
    let chunks = variables
        .iter()
        .zip(&block.columns)
        .map(|(v, column)| {
            let width = v.kind.values_per_cell(block.slots);
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
