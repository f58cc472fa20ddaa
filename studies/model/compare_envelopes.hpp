// bbm studies: `bbm compare --envelope` — the strength envelope of each compared
// model's rock (io::rock_of_model: its bonded region's blocks, bonds and
// material), measured as `bbm envelope` measures a rock.
#pragma once

#include "studies/lab/labtest_values.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace bbm::studies {

/// `bbm compare --envelope`: the strength envelope of each compared model's rock.
struct CompareEnvelopeOptions {
    bool enabled = false;
    /// Specimens smaller than the paper's 8 × 16 m by default: a deformable
    /// envelope at 8 × 16 m takes an hour or more on 2 cores; the ranking of the
    /// models is the same at 4 × 8 m (docs/notes/2026-11-28-calibration-history.md,
    /// "The strength envelope", measured both).
    double width = 4.0, height = 8.0;
    int realizations = 1;
    std::vector<double> confinements; ///< Pa; empty: 0.1–0.5 × each rock's UCS
};

/// Runs `bbm envelope` for the rock of each model into DIR/<model>/envelope/
/// (spread over threads and ranks like the envelope), writes DIR/envelopes.csv and
/// returns the Markdown table (UCS, T/UCS, Hoek–Brown and Mohr–Coulomb fits,
/// σ1 at the highest confinement, σci and σcd over the peak unconfined) that
/// `bbm compare` appends to comparison.md. Every rank calls it; rank 0's text is the table.
std::string compare_envelopes(const std::vector<std::string>& models, const std::filesystem::path& out, int threads,
                              bool quiet, const CompareEnvelopeOptions& options);

} // namespace bbm::studies
