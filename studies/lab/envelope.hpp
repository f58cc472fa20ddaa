// bbm studies: the strength envelope of a block model as a laboratory measures it
// (issue 23) — uniaxial compression, a tension test (direct or Brazilian) and
// biaxial compression at several confinements, N realizations each, spread over
// threads and MPI ranks like the other studies; then the fits a rock engineer
// reads a laboratory record with:
//   Hoek–Brown, intact rock (a = 0.5):  σ1 = σ3 + σci √(mi σ3/σci + 1)
//   Mohr–Coulomb:                        σ1 = σc + k σ3,  k = (1 + sin φ)/(1 − sin φ),
//                                        c = σc (1 − sin φ)/(2 cos φ)
// both by least squares on σ1 over every realization's peak (σ3 ≥ 0), with their
// RMS residual; the crack-initiation and crack-damage stresses at each confinement
// and the straight lines through them (the damage-initiation and crack-damage
// lines); the tension-to-compression ratio; the scatter over realizations.
// Stresses are compression positive; tension is reported as a positive strength.
//
// bbm is two-dimensional (plane strain): its "biaxial" test holds σ3 on the sides
// and the out-of-plane stress is whatever plane strain makes it, where a
// laboratory triaxial test has σ2 = σ3. docs/calibration.md says what that changes.
#pragma once

#include "studies/lab/labtest_values.hpp"

#include <string>
#include <vector>

namespace bbm::studies {

/// σ1 = σ3 + σci (mi σ3/σci + 1)^0.5 fitted to (σ3, σ1) points.
struct HoekBrownFit {
    double sigma_ci = 0.0, mi = 0.0;
    double rms = 0.0; ///< RMS of σ1 − fit over the points
    bool valid = false;
    double sigma1(double sigma3) const;
    /// The criterion's uniaxial tensile strength, positive: σci (√(mi² + 4) − mi) / 2.
    double tensile_strength() const;
};
/// Hoek's linearisation ((σ1 − σ3)² = σci² + mi σci σ3, linear least squares)
/// refined by Gauss–Newton on the σ1 residuals. Needs two or more distinct σ3.
HoekBrownFit fit_hoek_brown(const std::vector<double>& sigma3, const std::vector<double>& sigma1);

/// σ1 = σc + k σ3 by linear least squares, with c and φ from σc and k.
struct MohrCoulombFit {
    double cohesion = 0.0, friction_deg = 0.0, sigma_c = 0.0, slope = 0.0, rms = 0.0;
    bool valid = false; ///< false with fewer than two distinct σ3 or k < 1
};
MohrCoulombFit fit_mohr_coulomb(const std::vector<double>& sigma3, const std::vector<double>& sigma1);

/// y = intercept + slope x by least squares.
struct LineFit {
    double intercept = 0.0, slope = 0.0, rms = 0.0;
    bool valid = false;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

struct EnvelopeOptions {
    LabTestValues lab;                   ///< specimen, joints, realizations, threads (the lab-test flags)
    std::vector<double> confinements; ///< σ3 of the biaxial tests, Pa; empty: 0.1–0.5 × the measured UCS
    std::string tension_test = "direct"; ///< "direct", or "brazilian" (a disc)
    double brazilian_diameter = 4.0;  ///< m
    /// A laboratory record to draw beside the model's envelope: CSV of σ3, σ1 in
    /// MPa (a header line allowed), and/or a Hoek–Brown (σci, mi) to draw.
    std::string target_record;
    double target_sigma_ci = 0.0, target_mi = 0.0;
    bool replot = false; ///< envelope.png again from DIR/envelope.json, no test run
    /// A model file whose rock is tested (io::rock_of_model): its bonded region's
    /// pattern, seed, joints and blocks replace the lab flags' values; the
    /// specimen's size, loading and the study's flags still apply.
    std::string model;
};

/// One lab test of the envelope.
struct EnvelopeRun {
    std::string test; ///< "ucs", "tension", "brazilian", "biaxial"
    double confinement = 0.0;
    std::uint64_t seed = 0;
    LabTestResult result;
};

struct EnvelopeStudy {
    std::vector<EnvelopeRun> runs;
    std::string summary_json; ///< envelope.json
};

/// Runs the envelope, writes DIR/envelope.json, envelope.csv and envelope.png
/// (when lab.write_files). Returns 0. Throws InputError naming a flag.
int run_envelope(EnvelopeOptions& options, bool quiet, bool check_only, EnvelopeStudy* study = nullptr);



/// Reads a σ3, σ1 record (MPa, CSV; a first line that is not numbers is a header).
/// Returns pairs in Pa. Throws InputError naming the file and line.
std::vector<std::pair<double, double>> read_strength_record(const std::string& file);

} // namespace bbm::studies
