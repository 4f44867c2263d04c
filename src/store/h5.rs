//! Small HDF5 helpers shared by the atlas file and the tables: CF attributes, and dimension
//! scales through the HDF5 high-level library (`hdf5_hl`, linked by build.rs; neither the
//! `hdf5` crate nor `hdf5-metno-sys` binds `H5DS*`).

use crate::cf::{AttrValue, Units};
use hdf5::types::VarLenUnicode;
use std::ffi::{c_char, c_int, c_uint, CString};

extern "C" {
    fn H5DSset_scale(dsid: hdf5_sys::h5i::hid_t, dimname: *const c_char) -> c_int;
    fn H5DSattach_scale(
        did: hdf5_sys::h5i::hid_t,
        dsid: hdf5_sys::h5i::hid_t,
        idx: c_uint,
    ) -> c_int;
    fn H5DSis_attached(did: hdf5_sys::h5i::hid_t, dsid: hdf5_sys::h5i::hid_t, idx: c_uint)
        -> c_int;
    fn H5DSget_num_scales(did: hdf5_sys::h5i::hid_t, idx: c_uint) -> c_int;
}

/// Writes a scalar string attribute.
pub fn text_attr(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    let v: VarLenUnicode = value
        .parse()
        .map_err(|e: hdf5::types::StringError| hdf5::Error::from(e.to_string().as_str()))?;
    loc.new_attr::<VarLenUnicode>()
        .create(name)?
        .write_scalar(&v)
}

/// Writes a scalar attribute of the value's own type.
pub fn write_attr(loc: &hdf5::Location, name: &str, value: &AttrValue) -> hdf5::Result<()> {
    match value {
        AttrValue::Text(t) => text_attr(loc, name, t),
        AttrValue::Number(x) => loc.new_attr::<f64>().create(name)?.write_scalar(x),
        AttrValue::Integer(i) => loc.new_attr::<i64>().create(name)?.write_scalar(i),
    }
}

/// `long_name`, `units` and, for the paper's scaled quantities, `comment`.
pub fn describe(loc: &hdf5::Location, long_name: &str, units: Units) -> hdf5::Result<()> {
    text_attr(loc, "long_name", long_name)?;
    text_attr(loc, "units", units.units)?;
    if let Some(comment) = units.comment {
        text_attr(loc, "comment", comment)?;
    }
    Ok(())
}

/// `flag_values` (of the variable's type, u8) and `flag_meanings`.
pub fn flags(d: &hdf5::Dataset, (values, meanings): (&[u8], &str)) -> hdf5::Result<()> {
    d.new_attr::<u8>()
        .shape(values.len())
        .create("flag_values")?
        .write_raw(values)?;
    text_attr(d, "flag_meanings", meanings)
}

/// Makes `dataset` the dimension scale (coordinate) named `name`.
pub fn set_scale(dataset: &hdf5::Dataset, name: &str) -> hdf5::Result<()> {
    let name = CString::new(name).expect("dimension names have no NUL");
    let status = hdf5::sync::sync(|| unsafe { H5DSset_scale(dataset.id(), name.as_ptr()) });
    if status < 0 {
        return Err(format!("H5DSset_scale failed for {name:?}").as_str().into());
    }
    Ok(())
}

/// Attaches the dimension scale `scale` to dimension `index` of `dataset`.
pub fn attach_scale(
    dataset: &hdf5::Dataset,
    scale: &hdf5::Dataset,
    index: usize,
) -> hdf5::Result<()> {
    let status =
        hdf5::sync::sync(|| unsafe { H5DSattach_scale(dataset.id(), scale.id(), index as c_uint) });
    if status < 0 {
        return Err("H5DSattach_scale failed".into());
    }
    Ok(())
}

/// Whether `scale` is the one dimension scale attached to dimension `index` of `dataset`
/// (false where the dimension-scale attributes cannot be read).
pub fn is_attached(dataset: &hdf5::Dataset, scale: &hdf5::Dataset, index: usize) -> bool {
    let index = index as c_uint;
    hdf5::sync::sync(|| unsafe {
        H5DSget_num_scales(dataset.id(), index) == 1
            && H5DSis_attached(dataset.id(), scale.id(), index) > 0
    })
}

/// Whether every attribute of `loc` opens and its value reads (the dimension scales'
/// references, of types the `hdf5` crate does not describe, are opened only; their
/// content is checked by [`is_attached`]).
pub fn attributes_read(loc: &hdf5::Location) -> bool {
    use hdf5::types::TypeDescriptor as T;
    let Ok(names) = loc.attr_names() else {
        return false;
    };
    names.iter().all(|name| {
        let Ok(attr) = loc.attr(name) else {
            return false;
        };
        let Ok(dtype) = attr.dtype() else {
            return false;
        };
        match dtype.to_descriptor() {
            Ok(T::VarLenUnicode) => attr.read_raw::<VarLenUnicode>().is_ok(),
            Ok(T::Float(_)) => attr.read_raw::<f64>().is_ok(),
            Ok(T::Integer(_)) => attr.read_raw::<i64>().is_ok(),
            Ok(T::Unsigned(_)) => attr.read_raw::<u64>().is_ok(),
            _ => true,
        }
    })
}

/// The root (named "") and each dataset of `file`, in name order.
pub fn objects(file: &hdf5::File) -> hdf5::Result<Vec<(String, hdf5::Location)>> {
    let root: &hdf5::Location = file;
    let mut objects = vec![(String::new(), root.clone())];
    let mut names = file.member_names()?;
    names.sort();
    for name in names {
        let dataset = file.dataset(&name)?;
        let location: &hdf5::Location = &dataset;
        objects.push((name, location.clone()));
    }
    Ok(objects)
}

/// The CRC-32 of every variable-length text attribute of the root and of each dataset:
/// HDF5 keeps their letters in its global heap, which has no checksum. Over each object in
/// name order (the root as ""), each such attribute in name order, the bytes of
/// `object \0 name \0 value \0` (docs/files.md says so for other readers).
pub fn text_attributes_crc32(file: &hdf5::File) -> hdf5::Result<u32> {
    let mut crc = crc32fast::Hasher::new();
    for (object, location) in &objects(file)? {
        let mut attrs = location.attr_names()?;
        attrs.sort();
        for name in attrs {
            let attr = location.attr(&name)?;
            if !matches!(
                attr.dtype()?.to_descriptor(),
                Ok(hdf5::types::TypeDescriptor::VarLenUnicode)
            ) {
                continue;
            }
            let value = attr.read_scalar::<VarLenUnicode>()?;
            for part in [object.as_bytes(), name.as_bytes(), value.as_bytes()] {
                crc.update(part);
                crc.update(&[0]);
            }
        }
    }
    Ok(crc.finalize())
}
