//! Small HDF5 helpers shared by the writers: strings as variable-length UTF-8 (h5py reads them
//! as `str`), scalar and string attributes, 1-D datasets.

use hdf5::types::VarLenUnicode;
use hdf5::{H5Type, Location};
use ndarray::{arr0, ArrayView1};

/// Converts strings to HDF5 variable-length UTF-8.
pub(super) fn strings<S: AsRef<str>>(
    items: impl IntoIterator<Item = S>,
) -> hdf5::Result<Vec<VarLenUnicode>> {
    items
        .into_iter()
        .map(|s| {
            s.as_ref()
                .parse::<VarLenUnicode>()
                .map_err(|e| e.to_string().into())
        })
        .collect()
}

/// A 1-D dataset.
pub(super) fn dataset<T: H5Type>(
    group: &hdf5::Group,
    name: &str,
    data: &[T],
) -> hdf5::Result<hdf5::Dataset> {
    group
        .new_dataset_builder()
        .with_data(ArrayView1::from(data))
        .create(name)
}

/// A 1-D dataset with a `unit` attribute (`1` for a dimensionless or counting quantity).
pub(super) fn unit_dataset<T: H5Type>(
    group: &hdf5::Group,
    name: &str,
    data: &[T],
    unit: &str,
) -> hdf5::Result<hdf5::Dataset> {
    let d = dataset(group, name, data)?;
    str_attr(&d, "unit", unit)?;
    Ok(d)
}

/// A 1-D dataset whose entries have each their unit: a `unit` attribute of one string per
/// entry.
pub(super) fn units_dataset<T: H5Type, S: AsRef<str>>(
    group: &hdf5::Group,
    name: &str,
    data: &[T],
    units: impl IntoIterator<Item = S>,
) -> hdf5::Result<hdf5::Dataset> {
    let d = dataset(group, name, data)?;
    strs_attr(&d, "unit", units)?;
    Ok(d)
}

/// The root attributes every output file has: `schema`, `schema_version`, `tool_version` and
/// `created_by` (the command line), from `meta` (`docs/schemas.md`, "Every output").
pub(super) fn provenance(
    file: &hdf5::File,
    schema: &str,
    schema_version: i64,
    meta: &crate::run_meta::RunMeta,
) -> hdf5::Result<()> {
    str_attr(file, "schema", schema)?;
    scalar_attr(file, "schema_version", schema_version)?;
    str_attr(file, "tool_version", &meta.tool_version)?;
    str_attr(file, "created_by", &meta.command_line)
}

/// A scalar attribute.
pub(super) fn scalar_attr<T: H5Type>(loc: &Location, name: &str, value: T) -> hdf5::Result<()> {
    loc.new_attr_builder()
        .with_data(&arr0(value))
        .create(name)?;
    Ok(())
}

/// A scalar variable-length UTF-8 string attribute (h5py reads it as `str`).
pub(super) fn str_attr(loc: &Location, name: &str, value: &str) -> hdf5::Result<()> {
    let value = strings([value])?.pop().expect("one string in, one out");
    scalar_attr(loc, name, value)
}

/// A 1-D attribute of variable-length UTF-8 strings (h5py: object array of `str`).
pub(super) fn strs_attr<S: AsRef<str>>(
    loc: &Location,
    name: &str,
    values: impl IntoIterator<Item = S>,
) -> hdf5::Result<()> {
    let values = strings(values)?;
    loc.new_attr_builder()
        .with_data(ArrayView1::from(&values))
        .create(name)?;
    Ok(())
}
