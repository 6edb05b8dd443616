//! Symmetric patterns as graphs: their entries and their approximate-minimum-degree order,
//! for the normal matrix's structure (`pattern`) and its nested dissection (`ordering`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

/// The new label of every unknown in the approximate-minimum-degree order of a symmetric
/// pattern (its lower triangle, rows sorted in each column).
pub(super) fn amd_labels(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Option<Vec<usize>> {
    let (mut order, mut label) = (vec![0; n], vec![0; n]);
    let mut buffer = MemBuffer::try_new(amd::order_scratch::<usize>(n, row_idx.len())).ok()?;
    amd::order(
        &mut order,
        &mut label,
        SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx),
        amd::Control::default(),
        MemStack::new(&mut buffer),
    )
    .ok()?;
    Some(label)
}

/// The (row, column) entries of a compressed-column pattern, column by column.
pub(super) fn entries<'a>(
    col_ptr: &'a [usize],
    row_idx: &'a [usize],
) -> impl Iterator<Item = (usize, usize)> + 'a {
    (0..col_ptr.len() - 1).flat_map(move |c| {
        row_idx[col_ptr[c]..col_ptr[c + 1]]
            .iter()
            .map(move |&r| (r, c))
    })
}
