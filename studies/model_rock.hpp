// bbm studies: the rock of a model file as a laboratory specimen — the bonded
// region's block pattern, its material (rigid, or deformable with its fraction f)
// and the joint property its inner joints get, turned into the lab-test options
// (`bbm compare --envelope` measures each compared model's rock with them).
//
// A model's "rock" is its first region with a block pattern (not `single`); the
// property is the one the model's [[joint_assignment]] rules give the joints
// between two of its blocks (the rules in order, a later match overriding an
// earlier one, as the solver applies them). What a specimen cannot carry is
// refused with an InputError naming the model file and the key: trigon regions
// whose radial and peripheral joints get different properties, meshed blocks
// whose material has no deformable fraction, a rotated lattice, bricks of another
// aspect or bond, a given shortest edge.
#pragma once

#include "io/model_input.hpp"
#include "studies/labtest_values.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace bbm::studies {

/// The lab-test values for the rock of `model` (read from `file`, named in
/// errors): pattern, size and its measure, Lloyd iterations and seed of the
/// bonded region, its joint property (softening curves as they are), density,
/// and for meshed blocks the deformable fraction, modulus, Poisson's ratio and
/// triangle size. Specimen size, loading and the rest keep `base`'s values.
LabTestCli labtest_of_model(const io::ModelFile& model, const std::string& file, LabTestCli base = {});

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
