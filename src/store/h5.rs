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
