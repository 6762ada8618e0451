//! Where a film law's bottom-effect correction is used beyond the range it was derived for
//! (`chi = sqrt(R s) / h > 1`, MODEL.md section 9): the separations whose orbits indent the
//! film deeper than `h^2 / R`.

use crate::contact::ContactLaw;
use crate::model::TappingModel;

/// For a film law, a warning naming the range of `Z` (nm) among `orbits` (`(Z, lowest gap)`
/// pairs, `None` for an orbit without a gap minimum) whose lowest gap goes below `-h^2 / R`,
/// where `chi > 1`; `None` for another law or when every orbit stays inside the range.
pub fn film_range_warning(
    model: &TappingModel,
    orbits: impl IntoIterator<Item = (f64, Option<f64>)>,
) -> Option<String> {
    let ContactLaw::Film(film) = model.contact_force().law else {
        return None;
    };
    let deepest = film.deepest_valid_indentation_nm();
    let outside: Vec<f64> = orbits
        .into_iter()
        .filter(|(_, gap)| gap.is_some_and(|gap| -gap > deepest))
        .map(|(z, _)| z)
        .collect();
    let low = outside.iter().copied().reduce(f64::min)?;
    let high = outside.iter().copied().reduce(f64::max)?;
    Some(format!(
        "the film correction is used beyond chi = sqrt(R s)/h = 1 (indentation s > h^2/R = \
         {deepest:.4} nm, where it was derived) for Z in [{low:.4}, {high:.4}] nm"
    ))
}
