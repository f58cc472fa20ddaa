// The doctest main of the bbm test suite (tests are discovered by CTest).
//
// Test cases are of two kinds: unit tests (a closed form, an invariant, a small
// model, seconds) and validations (a lab test, a tunnel or a restart of one run to
// its answer, tens of seconds in Release), tagged `* doctest::test_suite("validation")`.
// The checking build (.ci/sanitize: sanitizers and assertions, 5-10 times slower)
// runs the unit tests: it sets BBM_SKIP_TEST_SUITES=validation, and a test case of
// a skipped suite exits with 77, which CTest reports as "Skipped" (SKIP_RETURN_CODE),
// not as passed.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include "tests/validation_record.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

/// How many test cases the run selected (after the suite filter).
unsigned selected_test_cases = 0;

struct SelectedCount : doctest::IReporter {
    explicit SelectedCount(const doctest::ContextOptions&) {}
    void report_query(const doctest::QueryData&) override {}
    void test_run_start() override {}
    void test_run_end(const doctest::TestRunStats& stats) override {
        selected_test_cases = stats.numTestCasesPassingFilters;
    }
    void test_case_start(const doctest::TestCaseData& data) override {
        // For tests/validation_record.hpp: which test case a record belongs to.
        bbm::test::current_test_case = data.m_name;
        const std::string file = data.m_file.c_str();
        const auto tests = file.rfind("tests/");
        bbm::test::current_test_file = tests == std::string::npos ? file : file.substr(tests);
    }
    void test_case_reenter(const doctest::TestCaseData&) override {}
    void test_case_end(const doctest::CurrentTestCaseStats&) override {}
    void test_case_exception(const doctest::TestCaseException&) override {}
    void subcase_start(const doctest::SubcaseSignature&) override {}
    void subcase_end() override {}
    void log_assert(const doctest::AssertData&) override {}
    void log_message(const doctest::MessageData&) override {}
    void test_case_skipped(const doctest::TestCaseData&) override {}
};
REGISTER_LISTENER("selected_count", 1, SelectedCount);

} // namespace

int main(int argc, char** argv) {
    doctest::Context context;
    const char* skipped_suites = std::getenv("BBM_SKIP_TEST_SUITES");
    const bool skipping = skipped_suites != nullptr && *skipped_suites != '\0';
    if (skipping) context.addFilter("test-suite-exclude", skipped_suites);
    context.applyCommandLine(argc, argv);
    const int result = context.run();
    if (context.shouldExit()) return result;
    constexpr int skipped = 77; // CTest's SKIP_RETURN_CODE for these tests
    if (skipping && result == 0 && selected_test_cases == 0) return skipped;
    // A filter that selects nothing passes silently in doctest: CTest would report
    // a test that never ran as passed (a ';' in a test's name cut CTest's filter
    // short: five tests did not run for weeks).
    if (!skipping && result == 0 && selected_test_cases == 0) {
        std::fprintf(stderr, "no test case matches the filter: not run (a ';' or ',' in its name?)\n");
        return 1;
    }
    return result;
}
