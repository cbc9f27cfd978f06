//! What a transfer-function file states beside its values, in CSV and HDF5 alike: whether it
//! has a floor translation input, and what the floor's motion is per unit of.

use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::tf::TransferMatrix;

/// True when `inputs` has a floor translation, whose convention the files then state.
pub(crate) fn has_translation(inputs: &[tiltnoise_core::tf::Input]) -> bool {
    inputs
        .iter()
        .any(|i| matches!(i, tiltnoise_core::tf::Input::Translation(_)))
}

/// What the floor's motion is per unit of, when not its displacement: the CSV note and the
/// HDF5 attribute `ground_quantity`.
pub(crate) fn ground_quantity_note(tf: &TransferMatrix) -> Option<String> {
    let q = tf.ground_quantity();
    (q != GroundQuantity::Displacement).then(|| {
        format!(
            "floor motion (tilt and translation inputs) per unit {}: the displacement's H \
             times {}",
            q.name(),
            match q {
                GroundQuantity::Velocity => "1/(i w)",
                _ => "-1/w^2",
            }
        )
    })
}
