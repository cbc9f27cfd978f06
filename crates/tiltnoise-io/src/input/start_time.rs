//! The start time of a series file of either kind (tilt or observables): HDF5 root attribute
//! `start_time`, CSV line `# start_time:`; validated ISO 8601. The measured-record reader
//! does not keep it, and the coherence job needs it to align the records.

use super::csv::{start_time, CsvFile};
use super::h5;
use super::{InputError, InputFormat};
use std::path::Path;

/// The ISO 8601 time of sample 0 that the file states, if any.
///
/// # Errors
///
/// The reader's errors: an extension other than `.h5`, `.hdf5`, `.csv`, a file that cannot be
/// opened, a `start_time` that is not a string or not ISO 8601.
pub fn read_start_time(path: &Path) -> Result<Option<String>, InputError> {
    match InputFormat::from_path(path)? {
        InputFormat::Hdf5 => {
            let file = h5::open(path)?;
            h5::start_and_description(path, &file, &mut Vec::new())
        }
        InputFormat::Csv => {
            let (_, prelude) = CsvFile::open(path)?;
            start_time(path, &prelude)
        }
        InputFormat::Miniseed => Err(InputError::UnknownLayout {
            path: path.to_path_buf(),
            format: "miniseed",
            found: "a miniSEED file, whose channels are named by SEED code, not by observable"
                .to_string(),
            accepted: "a record of the observables as HDF5 or CSV (X, Y, Z, theta, eta, phi, \
                       phi_a)",
        }),
    }
}
