//! Running the pipeline: [`Mesher::mesh_observed`] and its stages, the layout fallbacks,
//! and the region preparation of steps 1 and 1b.

use super::*;

impl Mesher {
    /// Target size of the submapping strategy (see the module documentation).
    fn submap_size(&self, region: &Region) -> f64 {
        match self.size {
            MeshSize::Cells(n) => (region.area() / n.max(1) as f64).sqrt(),
            MeshSize::CellSize(h) => h,
            MeshSize::Density(d) => {
                let shortest = region
                    .rings()
                    .flat_map(|r| {
                        let p = r.points();
                        (0..p.len()).map(move |i| p[i].distance(p[(i + 1) % p.len()]))
                    })
                    .fold(f64::INFINITY, f64::min);
                shortest / d.max(1) as f64
            }
        }
    }

    pub(super) fn stage(&mut self, s: Stage, msg: &str) {
        if let Some(f) = self.progress.as_mut() {
            f(s, msg);
        }
    }

    /// The width below which the pipeline itself leaves holes out of the layout: 0 with the
    /// default hole filter ([`HoleFilter::KeepAll`]), the width it set
    /// ([`Mesher::carve_islands`] or a retry); `None` when the user set a hole filter (the
    /// pipeline then leaves the holes alone) or the region is not simplified.
    fn auto_drop_width(&self) -> Option<f64> {
        match self.simplify.as_ref()?.holes {
            HoleFilter::KeepAll => Some(0.0),
            HoleFilter::MinWidth(w) if self.auto_dropped => Some(w),
            _ => None,
        }
    }

    /// Leaves the holes narrower than `width` ([`unamalla_contour::hole_width`]) out of the
    /// block layout of the next runs (the pipeline's own hole filter, whose holes are carved
    /// back where carving is on) and forgets the layouts excluded by earlier fallbacks.
    fn leave_out_holes_narrower(&mut self, width: f64) {
        if let Some(o) = self.simplify.as_mut() {
            o.holes = HoleFilter::MinWidth(width);
        }
        self.auto_dropped = true;
        self.excluded_layouts.clear();
    }

    /// The inverse of [`Mesher::leave_out_holes_narrower`]: every hole back in the block layout
    /// of the next runs (the default hole filter), the excluded layouts forgotten.
    fn keep_every_hole(&mut self) {
        if let Some(o) = self.simplify.as_mut() {
            o.holes = HoleFilter::KeepAll;
        }
        self.auto_dropped = false;
        self.excluded_layouts.clear();
    }

    /// One more whole run with the current options, verified and taken through the layout
    /// fallback ([`Mesher::layout_fallback`], whose notes go to `notes`); the error of a stage
    /// that failed.
    #[allow(clippy::type_complexity)]
    fn remake_with_fallback(
        &mut self,
        region: &Region,
        observer: &mut dyn Observer,
        verify: &dyn Fn(&MeshResult) -> crate::verify::Verification,
        notes: &mut Vec<String>,
    ) -> Result<
        (
            (MeshResult, crate::verify::Verification),
            (Option<String>, usize),
        ),
        CoreError,
    > {
        let retry = self.mesh_unverified(region, observer)?;
        let rv = verify(&retry);
        Ok(self.layout_fallback(region, observer, verify, (retry, rv), notes))
    }

    /// Pipeline steps 1 and 1b alone: the region simplified by the contour method
    /// ([`simplify_for_mesh`]) and then without the boundary features below the cell size
    /// ([`Mesher::feature_factor`]). The mesher meshes [`PreparedRegion::mesh_region`]; a
    /// decomposition file must have been made for it or for [`PreparedRegion::simplified`].
    pub fn prepare_region(&self, region: &Region) -> Result<PreparedRegion, CoreError> {
        // the holes the narrow-hole retry leaves out (indices into `region`), then the
        // simplification's own hole filter on the rest (its indices mapped back)
        let reduced;
        let (input, kept): (&Region, Vec<usize>) = if self.dropped_near_failure.is_empty() {
            (region, (0..region.holes().len()).collect())
        } else {
            let kept: Vec<usize> = (0..region.holes().len())
                .filter(|k| self.dropped_near_failure.binary_search(k).is_err())
                .collect();
            reduced = Region::new(
                region.outer().points().to_vec(),
                kept.iter()
                    .map(|&k| region.holes()[k].points().to_vec())
                    .collect(),
            )?;
            (&reduced, kept)
        };
        let (simplified, holes_dropped) = match &self.simplify {
            Some(opts) => {
                let r = simplify_for_mesh(input, opts)?;
                let mut dropped: Vec<usize> =
                    r.dropped_holes.iter().map(|h| kept[h.hole]).collect();
                dropped.extend_from_slice(&self.dropped_near_failure);
                dropped.sort_unstable();
                (r.region, dropped)
            }
            None => (input.clone(), self.dropped_near_failure.clone()),
        };
        let h = match self.size {
            MeshSize::Cells(n) => Some((simplified.area() / n.max(1) as f64).sqrt()),
            MeshSize::CellSize(h) => Some(h),
            MeshSize::Density(_) => None,
        };
        let mesh_region = match (h, &self.simplify) {
            (Some(h), Some(_)) if self.feature_factor > 0.0 => {
                remove_features_below(&simplified, self.feature_factor * h * h)?
            }
            _ => simplified.clone(),
        };
        let (mesh_region, necks) = match (h, &self.simplify) {
            (Some(h), Some(_)) if self.feature_factor > 0.0 && self.neck_factor > 0.0 => {
                unamalla_contour::cut_narrow_necks(
                    &mesh_region,
                    // sharp tips are not truncated: measured at 20,000 cells (θ₋ = 40°) it
                    // raised chesapeake-bay and norway above 90 % but lost 3 points on
                    // danish-straits and gulf-of-finland and left newfoundland with a cell
                    // outside the region (31 of 34 regions at target against 33); at 10° it
                    // fixed a needle peninsula but cost norway 3.9 points at 100,000 cells
                    // (docs/results.md, "Units, rotation and stretch")
                    &unamalla_contour::NeckOptions::new(self.neck_factor * h).with_tip_angle(0.0),
                )?
            }
            _ => (mesh_region, Vec::new()),
        };
        Ok(PreparedRegion {
            simplified,
            mesh_region,
            holes_dropped,
            necks,
        })
    }

    /// Runs the pipeline with no smoothing observer.
    pub fn mesh(self, region: &Region) -> Result<MeshResult, CoreError> {
        self.mesh_observed(region, &mut NullObserver)
    }

    /// Runs the pipeline; `observer` sees every smoothing iteration.
    ///
    /// Before the work: the size against the memory limit and the vertex count of an
    /// unsimplified region ([`crate::preflight`]). A stage failure caused by a too-narrow gap
    /// between rings is reported as such ([`crate::preflight::explain_failure`]). After the
    /// work, the mesh is checked independently ([`crate::verify::verify_quads`]: convex cells,
    /// centroids inside the meshed region, its area and hole count; the area against the input
    /// region within [`INPUT_AREA_TOLERANCE`] unless holes were dropped on purpose); a failure is
    /// [`CoreError::Guarantee`] unless [`Mesher::allow_non_convex`] was set. When the layout was
    /// chosen automatically and the mesh has non-convex cells or cells whose centroid lies outside
    /// the region, the mesh is re-made from the next candidate layouts (at most
    /// [`LAYOUT_FALLBACKS`] more runs; the report's notes name each layout that failed); when
    /// the mesh passes but its μ ≥ 0.8 share is below [`Mesher::quality_target`], at most
    /// [`QUALITY_FALLBACKS`] more candidates are tried and the best share is kept.
    pub fn mesh_observed(
        mut self,
        region: &Region,
        observer: &mut dyn Observer,
    ) -> Result<MeshResult, CoreError> {
        use crate::preflight;
        let t_start = Instant::now();
        let h = self.submap_size(region);
        let limit = preflight::memory_limit()?;
        let (option, value) = match self.size {
            MeshSize::Cells(0) => return Err(CoreError::ZeroCells),
            MeshSize::Cells(n) => ("--cells", n.to_string()),
            MeshSize::CellSize(h) => ("--cell-size", h.to_string()),
            MeshSize::Density(d) => ("--density", d.to_string()),
        };
        preflight::check_size(
            option,
            &value,
            region.area() / (h * h),
            "cells",
            preflight::COST_PER_MESH_CELL,
            limit,
        )?;
        let allow = self.allow_non_convex;
        // islands carved from the start ([`Mesher::carve_islands`])
        // (the number of holes it leaves out of the layout)
        let mut carved_from_start = 0;
        if self.carve_dropped && self.drop_narrow_holes && self.carve_width > 0.0 && h > 0.0 {
            let width = self.carve_width * h;
            let narrow = holes_narrower(region, width);
            if self.auto_drop_width() == Some(0.0) && narrow > 0 {
                self.leave_out_holes_narrower(width);
                carved_from_start = narrow;
            }
        }
        if self.simplify.is_none() && self.decomposition.is_none() {
            preflight::check_unsimplified(region)?;
            if !allow {
                preflight::check_narrow_features(region, h)?;
            }
        }
        let verify = |result: &MeshResult| {
            let mut v = crate::verify::verify_quads(
                result.mesh.global(),
                Some(&result.simplified),
                &crate::verify::VerifyOptions::default(),
            );
            if result.report.holes_dropped.is_empty() {
                v.input_area_defect = Some(result.report.area_change_percent / 100.0);
                v.input_area_tolerance = Some(INPUT_AREA_TOLERANCE);
            }
            v
        };
        let mut result = self
            .mesh_unverified(region, observer)
            .map_err(|e| preflight::explain_failure(e, region, h))?;
        let mut v = verify(&result);
        // fallback: a mesh of an automatically chosen layout with cells left folded (a block
        // whose transfinite start no untangling can fix, e.g. a side notched deeper than its
        // cells) or reaching out of the region (a boundary chord that skips a sharp reflex
        // vertex next to a block corner, with the cell behind it thinner than the excursion) is
        // re-made from the next candidate layout, best predicted first, at most
        // [`LAYOUT_FALLBACKS`] times; every attempt is named in the report's notes, and if none
        // passes, the attempt with the fewest such cells is the one reported
        let mut failed: Vec<String> = Vec::new();
        // the layout and the bad cells of the last attempt (the kept one may be an earlier one)
        let mut last;
        ((result, v), last) =
            self.layout_fallback(region, observer, &verify, (result, v), &mut failed);
        // carving from the start changed the layout (the narrow holes are not in it); when
        // that mesh fails the guarantee, the mesh keeping every hole in the layout is made too
        // and kept if it has fewer bad cells
        if !allow && !v.passed() && carved_from_start > 0 {
            let note = format!(
                "the mesh with the {carved_from_start} hole(s) narrower than {} cell size(s) left out of the layout failed the guarantee; made again with every hole in the layout",
                self.carve_width
            );
            self.stage(Stage::Decompose, &note);
            failed.push(note);
            self.keep_every_hole();
            if let Ok(((retry, rv), retry_last)) =
                self.remake_with_fallback(region, observer, &verify, &mut failed)
            {
                if rv.passed() || bad_cells(&rv) < bad_cells(&v) {
                    result = retry;
                    v = rv;
                    last = retry_last;
                }
            }
        }
        // holes narrower than a cell: with the default hole filter, a failure next to such a
        // hole is meshed again without every hole narrower than h ([`Mesher::drop_narrow_holes`])
        if !allow && !v.passed() && self.drop_narrow_holes && h > 0.0 {
            let default_filter = self.auto_drop_width().is_some();
            let narrow = holes_narrower(region, h);
            if default_filter && narrow > 0 && preflight::small_hole(&v, region, h).is_some() {
                // with carving, every hole at the cell scale (narrower than NEAR_HOLE_WIDTH · h)
                // leaves the layout, which then has no blocks a cell or two thick, and is carved
                // back into the smoothed mesh; without, only those narrower than a cell go
                let width = if self.carve_dropped {
                    NEAR_HOLE_WIDTH * h
                } else {
                    h
                };
                let dropped = holes_narrower(region, width);
                let note = if self.carve_dropped {
                    format!(
                        "the mesh keeping every hole failed the guarantee next to a hole narrower than the cell size {h:.4e}; made again with the {dropped} hole(s) narrower than {NEAR_HOLE_WIDTH} cell sizes left out of the block layout and carved back into the mesh"
                    )
                } else {
                    format!(
                        "the mesh keeping every hole failed the guarantee next to a hole narrower than the cell size {h:.4e}; made again without the {narrow} hole(s) narrower than that (a cell size of at most half their width keeps them)"
                    )
                };
                self.stage(Stage::Decompose, &note);
                self.leave_out_holes_narrower(width);
                let mut notes = vec![note];
                // round 0 without the holes narrower than a cell; each later round (at most
                // NEAR_HOLE_ROUNDS) also without the holes narrower than NEAR_HOLE_WIDTH · h
                // next to which the previous round failed
                let mut width = width;
                for round in 0..=NEAR_HOLE_ROUNDS {
                    // the layout fallback once more, on the region without those holes
                    let ((retry, rv), rv_last) = match self
                        .remake_with_fallback(region, observer, &verify, &mut notes)
                    {
                        Ok(attempt) => attempt,
                        // with carving, a decomposition that finds no cuts around the holes
                        // left is made again with wider holes left out (up to CARVE_MAX_WIDTH)
                        Err(e) if self.carve_dropped && 2.0 * width <= CARVE_MAX_WIDTH * h => {
                            width *= 2.0;
                            let note = format!(
                                "the layout without them failed ({e}); made again with the holes narrower than {} cell sizes left out and carved back in",
                                width / h
                            );
                            self.stage(Stage::Decompose, &note);
                            notes.push(note);
                            self.leave_out_holes_narrower(width);
                            continue;
                        }
                        Err(_) => break,
                    };
                    if rv.passed() {
                        failed.append(&mut notes);
                        result = retry;
                        v = rv;
                        last = rv_last;
                        break;
                    }
                    if round == NEAR_HOLE_ROUNDS {
                        break;
                    }
                    // the failing cells of the kept attempt, against the input's holes
                    let near: Vec<usize> =
                        preflight::holes_next_to_failures(&rv, region, h, h..NEAR_HOLE_WIDTH * h)
                            .into_iter()
                            .filter(|k| self.dropped_near_failure.binary_search(k).is_err())
                            .collect();
                    if near.is_empty() {
                        break;
                    }
                    let note = format!(
                        "the mesh without the holes narrower than a cell failed the guarantee next to {} hole(s) narrower than {NEAR_HOLE_WIDTH} cell sizes ({}); made again without them too",
                        near.len(),
                        near.iter().map(|k| k.to_string()).collect::<Vec<_>>().join(", ")
                    );
                    self.stage(Stage::Decompose, &note);
                    notes.push(note);
                    self.dropped_near_failure.extend(near);
                    self.dropped_near_failure.sort_unstable();
                    self.excluded_layouts.clear();
                }
            }
        }
        // quality fallback: a mesh that passed but is below the quality target is re-made from
        // the next candidate layouts (best predicted first), keeping the best achieved share
        let mut quality_tries = 0;
        // the share of the last attempt (the kept one may be an earlier one)
        let mut last_share = result.report.mu_ge_0_8_percent;
        // whether the last attempt failed the guarantee (then the note names the kept mesh: the
        // attempt's own share may be above the target)
        let mut last_failed = false;
        while !allow
            && self.quality_target > 0.0
            && v.passed()
            && result.report.mu_ge_0_8_percent < self.quality_target
            && quality_tries < QUALITY_FALLBACKS
        {
            let Some(name) = last.0.take() else {
                break;
            };
            quality_tries += 1;
            let note = if !last_failed {
                format!(
                    "layout {name} reached μ ≥ 0.8 on {last_share:.1} % of the cells, below the target {} %; re-made from the next candidate layout",
                    self.quality_target
                )
            } else {
                format!(
                    "layout {name} failed the guarantee; the mesh kept so far (layout {}) reached μ ≥ 0.8 on {:.1} % of the cells, below the target {} %; re-made from the next candidate layout",
                    layout_name(&result).as_deref().unwrap_or("?"),
                    result.report.mu_ge_0_8_percent,
                    self.quality_target
                )
            };
            let Some((retry, rv)) =
                self.remake_excluding(name, note, &mut failed, region, observer, &verify)
            else {
                break;
            };
            last = (layout_name(&retry), bad_cells(&rv));
            let share = retry.report.mu_ge_0_8_percent;
            last_share = share;
            failed.push(format!(
                "layout {} reached μ ≥ 0.8 on {share:.1} % ({})",
                last.0.as_deref().unwrap_or("?"),
                verdict(rv.passed(), share > result.report.mu_ge_0_8_percent)
            ));
            last_failed = !rv.passed();
            if rv.passed() && share > result.report.mu_ge_0_8_percent {
                result = retry;
                v = rv;
            }
        }
        // islands carved instead of bridged: a mesh that passed but stayed below the quality
        // target, in a region with holes narrower than NEAR_HOLE_WIDTH · h (the layout gives each
        // blocks a cell or two thick), is made once more with those holes left out of the layout
        // and carved back into the mesh ([`Mesher::carve_dropped_holes`]), and kept if it passes
        // with a higher share; if it does not (or the decomposition finds no cuts around the
        // holes left), once more with the holes twice as wide, up to CARVE_MAX_WIDTH · h
        if !allow
            && v.passed()
            && self.quality_target > 0.0
            && result.report.mu_ge_0_8_percent < self.quality_target
            && self.carve_dropped
            && self.drop_narrow_holes
            && h > 0.0
            && self
                .auto_drop_width()
                .is_some_and(|w| w < NEAR_HOLE_WIDTH * h)
        {
            let mut width = NEAR_HOLE_WIDTH * h;
            while width <= CARVE_MAX_WIDTH * h {
                let small = holes_narrower(region, width);
                if small == 0 {
                    break;
                }
                let note = format!(
                    "μ ≥ 0.8 on {:.1} % of the cells, below the target {} %; made again with the {small} hole(s) narrower than {} cell sizes left out of the block layout and carved back into the mesh",
                    result.report.mu_ge_0_8_percent,
                    self.quality_target,
                    width / h
                );
                self.stage(Stage::Decompose, &note);
                failed.push(note);
                self.leave_out_holes_narrower(width);
                match self.remake_with_fallback(region, observer, &verify, &mut failed) {
                    Ok(((retry, rv), _)) => {
                        let share = retry.report.mu_ge_0_8_percent;
                        let kept = rv.passed() && share > result.report.mu_ge_0_8_percent;
                        failed.push(format!(
                            "with the islands carved: μ ≥ 0.8 on {share:.1} % ({})",
                            verdict(rv.passed(), share > result.report.mu_ge_0_8_percent)
                        ));
                        if kept {
                            result = retry;
                            v = rv;
                            break;
                        }
                        // the islands left in the layout still keep it below: carve wider ones
                        width *= 2.0;
                    }
                    // the decomposition found no cuts around the holes left: carve wider ones
                    Err(e) => {
                        failed.push(format!("the layout without them failed ({e})"));
                        width *= 2.0;
                    }
                }
            }
        }
        if !failed.is_empty() {
            result.report.seconds = t_start.elapsed().as_secs_f64();
            let mut notes = failed;
            notes.append(&mut result.report.notes);
            result.report.notes = notes;
        }
        result.report.verification = v.clone();
        if !allow {
            v.into_result()
                .map_err(|e| preflight::explain_guarantee(e, region, h))?;
        }
        Ok(result)
    }

    /// The layout fallback of [`Mesher::mesh_observed`]: while the kept attempt `best` fails
    /// the guarantee with non-convex cells or cells outside the region, the mesh is re-made from
    /// the next candidate layout (the last attempt's layout excluded), at most
    /// [`LAYOUT_FALLBACKS`] times, each named in `notes`; the attempt with the fewest such cells
    /// is kept (the earlier on a tie; a passing one always). Returns the kept attempt and the
    /// layout and bad-cell count of the last one.
    fn layout_fallback(
        &mut self,
        region: &Region,
        observer: &mut dyn Observer,
        verify: &dyn Fn(&MeshResult) -> crate::verify::Verification,
        best: (MeshResult, crate::verify::Verification),
        notes: &mut Vec<String>,
    ) -> (
        (MeshResult, crate::verify::Verification),
        (Option<String>, usize),
    ) {
        let (mut result, mut v) = best;
        let mut last = (layout_name(&result), bad_cells(&v));
        let mut tries = 0;
        while !self.allow_non_convex && !v.passed() && last.1 > 0 && tries < LAYOUT_FALLBACKS {
            let (Some(name), bad) = (last.0.take(), last.1) else {
                break;
            };
            tries += 1;
            let note = format!(
                "layout {name} left {bad} cell(s) non-convex or outside the region; re-made from the next candidate layout"
            );
            // no candidate left, or the next one fails in a stage: keep what we have
            let Some((retry, rv)) =
                self.remake_excluding(name, note, notes, region, observer, verify)
            else {
                break;
            };
            last = (layout_name(&retry), bad_cells(&rv));
            if rv.passed() || bad_cells(&rv) < bad_cells(&v) {
                result = retry;
                v = rv;
            }
        }
        ((result, v), last)
    }

    /// One retry of the fallbacks of [`Mesher::mesh_observed`]: `note` goes to the progress
    /// line and to `notes`, layout `name` is excluded, and the mesh is re-made from the next
    /// candidate layout and verified; `None` when no candidate is left or a stage fails.
    fn remake_excluding(
        &mut self,
        name: String,
        note: String,
        notes: &mut Vec<String>,
        region: &Region,
        observer: &mut dyn Observer,
        verify: &dyn Fn(&MeshResult) -> crate::verify::Verification,
    ) -> Option<(MeshResult, crate::verify::Verification)> {
        self.stage(Stage::Decompose, &note);
        notes.push(note);
        self.excluded_layouts.push(name);
        let retry = self.mesh_unverified(region, observer).ok()?;
        let rv = verify(&retry);
        Some((retry, rv))
    }

    /// Pipeline steps 7a (local untangling patches) and 7b (the global smoothing run, ended by
    /// the convergence tests of `sopts.solver.stop`) on `mesh`; returns the smoother's status.
    pub(super) fn untangle_and_smooth(
        &mut self,
        mesh: &mut BlockMesh2,
        sopts: &SmoothOptions,
        t_stage: Instant,
        observer: &mut dyn Observer,
    ) -> Result<String, CoreError> {
        let mut sopts = sopts.clone();
        // 7a. the folded cells (TFI of a wiggly block) are untangled in local patches across
        // block boundaries ([`crate::untangle`]): small problems converge in far fewer
        // iterations than the global one, the work is bounded by iteration limits (not
        // wall-clock time, so the result does not depend on the load), and the global run
        // below then starts convex (or nearly so)
        let patches = crate::untangle::untangle_patches_observed(
            mesh.global_mut(),
            &sopts,
            &crate::untangle::DEFAULT_PATCH_RADII,
            observer,
        )?;
        if patches.before > 0 {
            mesh.sync_blocks();
            let msg = format!(
                "untangled {} → {} non-convex cells in {} local patch(es) (radius ≤ {}, {} iterations, {:.2} s)",
                patches.before,
                patches.after,
                patches.patches,
                patches.max_radius,
                patches.iterations,
                t_stage.elapsed().as_secs_f64()
            );
            self.stage(Stage::Smooth, &msg);
            if !patches.unresolved.is_empty() {
                let msg = format!(
                    "{} fold(s) could not be removed by local patches{} (cells {:?}{}); left to the global run",
                    patches.unresolved.len(),
                    if patches.cancelled { " (cancelled)" } else { "" },
                    &patches.unresolved[..patches.unresolved.len().min(8)],
                    if patches.unresolved.len() > 8 { ", …" } else { "" },
                );
                self.stage(Stage::Smooth, &msg);
            }
        }
        // 7b. the global run, ended by the convergence tests of `sopts.solver.stop`
        if let Some(t) = self.time_limit {
            sopts.time_limit = Some((t - t_stage.elapsed().as_secs_f64()).max(0.0));
        }
        let smoothing = smooth(mesh, &sopts, observer)?;
        mesh.sync_blocks();
        Ok(smoothing.status.to_string())
    }

    /// The pipeline without the checks of [`Mesher::mesh_observed`].
    fn mesh_unverified(
        &mut self,
        region: &Region,
        observer: &mut dyn Observer,
    ) -> Result<MeshResult, CoreError> {
        let t0 = Instant::now();
        let mut stage_seconds = Vec::new();
        let mut timer = Instant::now();
        let mut lap = |s: Stage, timer: &mut Instant| {
            stage_seconds.push((s, timer.elapsed().as_secs_f64()));
            *timer = Instant::now();
        };

        // 1. simplify, 1b. remove the features below the cell size
        self.stage(Stage::Simplify, "simplifying the contour");
        let prepared = self.prepare_region(region)?;
        let mut holes_dropped = prepared.holes_dropped;
        // the dropped holes carved back in (step 7b′) and the note saying so
        let mut holes_carved: Vec<usize> = Vec::new();
        let mut carve_notes: Vec<String> = Vec::new();
        // with islands carved: the block of the layout each block of the mesh is part of
        let mut block_origin: Option<Vec<usize>> = None;
        let neck_notes: Vec<String> = prepared.necks.iter().map(|c| c.to_string()).collect();
        // a decomposition file fits either region: ours (saved by a previous run) fits the one
        // without features, one made by hand for the simplified region fits the other
        // (validated here, once: the error names the simplified region when neither fits)
        let mut simplified = match &self.decomposition {
            Some(d) if d.validate(&prepared.mesh_region).is_err() => {
                d.validate(&prepared.simplified)?;
                prepared.simplified
            }
            _ => prepared.mesh_region,
        };
        lap(Stage::Simplify, &mut timer);

        // 2–6 by submapping (Ruiz-Gironés & Sarrate) when the strategy asks for it
        // notes of step 3 for the report (cells the counts cannot avoid)
        let mut counts_notes: Vec<String> = Vec::new();
        let submapping = match (self.strategy, self.decomposition.is_some()) {
            (Strategy::Submap, true) => return Err(CoreError::DecompositionWithSubmap),
            (Strategy::Submap, false) => {
                self.stage(Stage::Decompose, "submapping (Ruiz-Gironés & Sarrate)");
                Some(submap(
                    &simplified,
                    &SubmapOptions::new(self.submap_size(&simplified)),
                )?)
            }
            (Strategy::Auto, false) if prefers_submap(&simplified, AUTO_ANGLE_TOLERANCE_DEG) => {
                self.stage(
                    Stage::Decompose,
                    "submapping (Ruiz-Gironés & Sarrate, automatic choice)",
                );
                submap(
                    &simplified,
                    &SubmapOptions::new(self.submap_size(&simplified)),
                )
                .ok()
            }
            _ => None,
        };
        let mut layout_choice: Option<LayoutChoice> = None;
        let (decomposition, counts, mut mesh) = match submapping.as_ref() {
            Some(s) => {
                lap(Stage::Decompose, &mut timer);
                lap(Stage::Counts, &mut timer);
                self.stage(Stage::Tfi, "transfinite interpolation per piece");
                let grids = s.grids()?;
                lap(Stage::Tfi, &mut timer);
                self.stage(Stage::Merge, "merging pieces");
                let mesh = BlockMesh2::merge(grids, 1e-9)?;
                lap(Stage::Merge, &mut timer);
                (s.to_decomposition(), None, mesh)
            }
            None => {
                // 2. decompose
                self.stage(Stage::Decompose, "decomposing into blocks");
                let decomposition = match self.decomposition.take() {
                    Some(d) => d,
                    None => {
                        // the chord layout samples the boundary at the cell size
                        let mut opts = self.decompose_opts.clone();
                        if opts.cell_size.is_none() {
                            opts.cell_size = match self.size {
                                MeshSize::Cells(n) => {
                                    Some((simplified.area() / n.max(1) as f64).sqrt())
                                }
                                MeshSize::CellSize(h) => Some(h),
                                MeshSize::Density(_) => None,
                            };
                        }
                        match self.layout {
                            Some(l) => {
                                opts.layout = l;
                                decompose(&simplified, &opts)?
                            }
                            None => {
                                let (d, choice) = choose_layout_excluding(
                                    &simplified,
                                    &opts,
                                    self.size,
                                    &self.excluded_layouts,
                                )?;
                                layout_choice = Some(choice);
                                d
                            }
                        }
                    }
                };
                lap(Stage::Decompose, &mut timer);

                // 3. compatible counts
                self.stage(Stage::Counts, "solving for compatible point counts");
                let step3 = crate::curves::compatible_counts(&decomposition, self.size)?;
                counts_notes = step3.notes;
                let (curves, counts) = (step3.curves, step3.solution);
                lap(Stage::Counts, &mut timer);

                // 4–5. reparametrize + TFI
                self.stage(Stage::Tfi, "transfinite interpolation per block");
                let grids = curves.grids(&decomposition, &counts.counts)?;
                lap(Stage::Tfi, &mut timer);

                // 6. merge
                self.stage(Stage::Merge, "merging blocks");
                let mesh = BlockMesh2::merge(grids, 1e-9)?;
                lap(Stage::Merge, &mut timer);
                (decomposition, Some(counts), mesh)
            }
        };

        // 6b. flat block corners on the boundary (triangle blocks): bent outward so their
        // cells can be convex
        let bent_corners =
            crate::flat_corners::bend_flat_corners(&mut mesh, self.flat_corner_deficit);

        // 7. smooth (region boundary fixed, cut nodes free)
        // (a mesh without interior nodes — every node on the region boundary, e.g. one cell
        // per block — has nothing to smooth: it is kept as the transfinite interpolation made it)
        let smoothing_status = if mesh.global().num_free() == 0 {
            self.stage(Stage::Smooth, "no interior node: nothing to smooth");
            lap(Stage::Smooth, &mut timer);
            "not smoothed: the mesh has no interior node".to_string()
        } else {
            self.stage(Stage::Smooth, "smoothing (convexity-preserving)");
            let mut sopts = self.smooth_opts.clone();
            if let unamalla_optim::SmoothFunctional::BlockSmoothing { density, .. } =
                &mut sopts.functional
            {
                *density = self.boundary_density;
            }
            // the explicit time limit (if any) counts from the start of the stage
            let t_stage = Instant::now();
            sopts.time_limit = self.time_limit;
            // 7-. a start prolonged from smoothed coarse levels ([`crate::multilevel`]); when it is
            // used, the untangling below has nothing to do (the start is convex)
            let coarse = match (&counts, submapping.is_none()) {
                (Some(c), true) => crate::multilevel::coarse_start(
                    &decomposition,
                    self.size,
                    &mesh,
                    &c.counts,
                    &sopts,
                    crate::multilevel::CoarseLevels {
                        levels: self.coarse_levels,
                        flat_corner_deficit: self.flat_corner_deficit,
                    },
                    observer,
                )?,
                _ => None,
            };
            if let Some(c) = &coarse {
                self.stage(Stage::Smooth, &c.summary());
                if c.accepted {
                    mesh.global_mut().nodes_mut().copy_from_slice(&c.nodes);
                    sopts = crate::multilevel::polish_options(&sopts);
                }
            }
            let status = self.untangle_and_smooth(&mut mesh, &sopts, t_stage, observer)?;
            // 7b′. islands the narrow-hole retry left out of the layout, carved back in
            // ([`crate::carve`]) and the carved mesh smoothed again
            if self.carve_dropped && self.auto_dropped && !holes_dropped.is_empty() {
                self.stage(Stage::Smooth, "carving the islands left out of the layout");
                let islands = super::islands::Islands {
                    input: region,
                    simplified: &simplified,
                    dropped: &holes_dropped,
                };
                let (step, note) = self.carve_dropped(&mesh, islands, &sopts, t_stage, observer)?;
                self.stage(Stage::Smooth, &note);
                carve_notes.push(note);
                if let Some(c) = step {
                    block_origin = Some(c.origin);
                    mesh = c.mesh;
                    simplified = c.region;
                    holes_dropped.retain(|k| c.carved.binary_search(k).is_err());
                    holes_carved = c.carved;
                }
            }
            lap(Stage::Smooth, &mut timer);
            status
        };

        // 7c. local shape improvement, the region-boundary nodes sliding along the boundary
        // ([`unamalla_optim::shape`]): the smoother keeps them where the transfinite
        // interpolation put them, so rows of cells meeting the boundary obliquely stay sheared
        let shape = match self.shape.clone() {
            Some(o) if o.max_sweeps > 0 => {
                self.stage(Stage::Shape, "shape pass (boundary nodes sliding)");
                let slide = BoundarySlide::new(mesh.global(), &simplified, o.feature_angle_deg);
                let r = improve_shape(mesh.global_mut(), Some(&slide), &o, observer);
                mesh.sync_blocks();
                self.stage(
                    Stage::Shape,
                    &format!(
                        "shape pass: μ ≥ {} on {:.1} → {:.1} % of the cells ({} sweeps, {} moves, {} slides)",
                        o.keep, r.good_before, r.good_after, r.sweeps, r.moved, r.slid
                    ),
                );
                lap(Stage::Shape, &mut timer);
                Some(r)
            }
            _ => None,
        };

        // 8. report
        self.stage(Stage::Report, "quality report");
        let quality = QualityReport::for_quads(&mesh);
        let q = quality.quad.as_ref();
        let sj = quality.metric("scaled_jacobian");
        let mesh_area: f64 = (0..mesh.num_quads())
            .map(|c| unamalla_mesh::region::signed_area(&mesh.quad_points(c)))
            .sum();
        let area_change_percent = (mesh_area - region.area()).abs() / region.area() * 100.0;
        let hausdorff = boundary_hausdorff(&mesh, region);
        lap(Stage::Report, &mut timer);
        let report = MeshReport {
            region: String::new(),
            cells: mesh.num_quads(),
            nodes: mesh.num_nodes(),
            blocks: mesh.blocks().len(),
            strategy: if submapping.is_some() {
                Strategy::Submap
            } else {
                Strategy::Cuts
            },
            non_convex_cells: quality.non_convex_cells,
            interior_singularities: q.map_or(0, |q| q.interior_singularities),
            bent_corners,
            mu_ge_0_8_percent: q.map_or(0.0, |q| q.mu_bands.good),
            mu_bands: q.map_or([0.0; 3], |q| {
                [q.mu_bands.good, q.mu_bands.fair, q.mu_bands.poor]
            }),
            min_scaled_jacobian: sj.map_or(f64::NAN, |m| m.min),
            p5_scaled_jacobian: sj.map_or(f64::NAN, |m| m.p5),
            min_alpha_over_mean: q.map_or(f64::NAN, |q| q.alpha_min_ratio),
            area_change_percent,
            hausdorff,
            holes_dropped,
            holes_carved,
            smoothing: smoothing_status,
            shape,
            seconds: t0.elapsed().as_secs_f64(),
            stage_seconds,
            block_quality: layout_choice
                .as_ref()
                .map(|c| {
                    // the mesh blocks of each layout block (one, or the pieces around its
                    // carved islands)
                    let parts = |b: usize| -> Vec<usize> {
                        match &block_origin {
                            None if b < mesh.blocks().len() => vec![b],
                            None => Vec::new(),
                            Some(o) => (0..o.len()).filter(|&k| o[k] == b).collect(),
                        }
                    };
                    c.blocks
                        .iter()
                        .enumerate()
                        .filter_map(|(b, &p)| {
                            let (mut good, mut cells) = (0.0, 0);
                            for k in parts(b) {
                                let (a, n) = crate::predict::block_good_share(&mesh, k);
                                good += a * n as f64;
                                cells += n;
                            }
                            (cells > 0).then(|| BlockQuality {
                                block: b,
                                cells,
                                predicted: 100.0 * p,
                                achieved: 100.0 * good / cells as f64,
                            })
                        })
                        .collect()
                })
                .unwrap_or_default(),
            layout: layout_choice,
            quality,
            notes: neck_notes
                .into_iter()
                .chain(counts_notes)
                .chain(carve_notes)
                .collect(),
            verification: Default::default(),
        };
        Ok(MeshResult {
            simplified,
            decomposition,
            counts,
            submap: submapping,
            mesh,
            report,
        })
    }
}

/// The region after pipeline steps 1 and 1b ([`Mesher::prepare_region`]).
#[derive(Debug, Clone)]
pub struct PreparedRegion {
    /// After the contour simplification ([`simplify_for_mesh`]); the input region itself
    /// without simplification.
    pub simplified: Region,
    /// After the removal of boundary features below the cell size: the region that is meshed.
    pub mesh_region: Region,
    /// Input holes dropped by the simplification (indices in input order).
    pub holes_dropped: Vec<usize>,
    /// Spits and inlets cut off at their necks ([`Mesher::neck_factor`]).
    pub necks: Vec<unamalla_contour::NeckCut>,
}

/// Largest relative area change (a fraction) the pipeline accepts from the contour
/// simplification before it retries with a smaller threshold (see [`simplify_for_mesh`]).
pub const MAX_SIMPLIFY_AREA_CHANGE: f64 = 0.01;

/// The contour simplification of pipeline step 1: [`simplify_region`] with `opts`, retried with
/// the threshold ε halved (at most six times) while the region's area changes by more than
/// [`MAX_SIMPLIFY_AREA_CHANGE`] — unless the finer result has a vertex almost touching another
/// edge (closer than 10⁻⁶ of the region's size), which the coarser one had removed. The thesis's default thresholds are tuned for dense, noisy
/// contours; on a coarse silhouette of a few dozen vertices the same ε removes real shape (the
/// bundled `horse` lost 2.1 % of its area). Use this function to reproduce the pipeline's
/// simplified region (e.g. to validate a decomposition file against it).
pub fn simplify_for_mesh(
    region: &Region,
    opts: &SimplifyOptions,
) -> Result<unamalla_contour::SimplifyResult, CoreError> {
    let mut r = simplify_region(region, opts)?;
    for _ in 0..6 {
        if r.relative_area_change.abs() <= MAX_SIMPLIFY_AREA_CHANGE {
            break;
        }
        let smaller = opts.clone().epsilon(Some(0.5 * r.epsilon));
        let retry = simplify_region(region, &smaller)?;
        // keep the coarser result when the finer one brings back a near contact (a vertex
        // within 10⁻⁶ of the region's size of a non-adjacent edge): no mesh can resolve it
        if nearly_touching(&retry.region, 1e-6) {
            break;
        }
        r = retry;
    }
    Ok(r)
}

/// Whether some vertex of `region` lies within `rel·diag` (diag = bounding-box diagonal) of an
/// edge of any ring other than its two own edges.
fn nearly_touching(region: &Region, rel: f64) -> bool {
    let (lo, hi) = region.bounding_box();
    let tol = rel * (hi - lo).length();
    let index = region.edge_index();
    let rings = index.rings();
    rings.iter().enumerate().any(|(ri, ring)| {
        let n = ring.len();
        ring.iter().enumerate().any(|(i, &p)| {
            let d = DVec2::splat(tol);
            index.candidates(p - d, p + d).any(|e| {
                let own = e.ring == ri && (e.edge == i || (e.edge + 1) % n == i);
                let (a, b) = index.edge(e);
                !own && unamalla_mesh::geometry::point_segment_distance(p, a, b) <= tol
            })
        })
    })
}

/// The automatically chosen layout of a mesh (`None`: the layout was given).
/// What became of a retry, for its note: kept when it passed the guarantee and is `better`.
fn verdict(passed: bool, better: bool) -> &'static str {
    match (passed, better) {
        (false, _) => "failed the guarantee: not kept",
        (true, true) => "kept",
        (true, false) => "not better: not kept",
    }
}

fn layout_name(result: &MeshResult) -> Option<String> {
    result.report.layout.as_ref().map(|c| c.layout.clone())
}

/// The cells a layout fallback counts against an attempt: non-convex, or with the centroid
/// outside the region.
/// The number of holes of `region` narrower than `width` ([`unamalla_contour::hole_width`]).
fn holes_narrower(region: &Region, width: f64) -> usize {
    region
        .holes()
        .iter()
        .filter(|hole| unamalla_contour::hole_width(hole) < width)
        .count()
}

fn bad_cells(v: &crate::verify::Verification) -> usize {
    v.non_convex_cells + v.centroids_outside.unwrap_or(0)
}

/// The Hausdorff distance between the mesh's boundary loops and the region's rings: each mesh
/// loop is compared with the input ring it approximates (the outer loop with the outer ring, each
/// hole loop with the input hole whose centroid is nearest).
fn boundary_hausdorff(mesh: &BlockMesh2, region: &Region) -> f64 {
    let loops = unamalla_io::msh::boundary_loops(mesh);
    let nodes = mesh.nodes();
    let centroid = |p: &[DVec2]| p.iter().copied().sum::<DVec2>() / p.len().max(1) as f64;
    let mut worst: f64 = 0.0;
    for l in &loops {
        let pts: Vec<DVec2> = l.edges.iter().map(|e| nodes[e[0]]).collect();
        let target = if l.signed_area > 0.0 {
            region.outer().points()
        } else {
            let c = centroid(&pts);
            match region.holes().iter().min_by(|a, b| {
                centroid(a.points())
                    .distance(c)
                    .total_cmp(&centroid(b.points()).distance(c))
            }) {
                Some(h) => h.points(),
                None => continue,
            }
        };
        worst = worst.max(unamalla_contour::hausdorff(&pts, target));
    }
    worst
}
