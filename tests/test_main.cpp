// The test runner's main: doctest's, plus an exit status that tells ctest when
// a test case was skipped rather than passed.
//
// A test case that needs an optional part (Embree, MPI, SDL2, an AVX2 or AVX-512
// CPU) says so in its name, "... [needs Embree]", and is decorated
// `* doctest::skip(!available)`. ctest runs each test case on its own
// (doctest_discover_tests); when every test case a run selects is skipped, the
// run exits with kSkippedExitCode, which CMakeLists.txt declares as
// SKIP_RETURN_CODE, so ctest lists it as "Not Run" with the reason in its name.
// Test case names must not contain ';' (CMake splits lists there).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cstdio>
#include <cstring>
#include <sstream>
#include <vector>

namespace {

constexpr int kSkippedExitCode = 77;

/// Counts the test cases that started, and keeps what a listing query returned.
struct RunRecord : doctest::IReporter {
    static inline int started = 0;
    static inline std::vector<const doctest::TestCaseData*> listed;

    explicit RunRecord(const doctest::ContextOptions&) {}
    void report_query(const doctest::QueryData& q) override { listed.assign(q.data, q.data + q.num_data); }
    void test_run_start() override {}
    void test_run_end(const doctest::TestRunStats&) override {}
    void test_case_start(const doctest::TestCaseData&) override { ++started; }
    void test_case_reenter(const doctest::TestCaseData&) override {}
    void test_case_end(const doctest::CurrentTestCaseStats&) override {}
    void test_case_exception(const doctest::TestCaseException&) override {}
    void subcase_start(const doctest::SubcaseSignature&) override {}
    void subcase_end() override {}
    void log_assert(const doctest::AssertData&) override {}
    void log_message(const doctest::MessageData&) override {}
    void test_case_skipped(const doctest::TestCaseData&) override {}
};

REGISTER_LISTENER("sahara_run_record", 1, RunRecord);

/// Whether the command line asks for the list of test cases (-ltc, --list-test-cases,
/// with or without doctest's "dt-" prefix).
bool lists_test_cases(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const char* a = argv[i];
        while (*a == '-') ++a;
        if (std::strncmp(a, "dt-", 3) == 0) a += 3;
        if (std::strcmp(a, "ltc") == 0 || std::strcmp(a, "list-test-cases") == 0) return true;
    }
    return false;
}

/// The test cases the filters on the command line select, skipped ones included.
std::vector<const doctest::TestCaseData*> selected_test_cases(int argc, char** argv) {
    std::vector<char*> args(argv, argv + argc);
    char list_flag[] = "--list-test-cases";  // a flag: Context::setOption does not set it
    args.push_back(list_flag);
    doctest::Context query(int(args.size()), args.data());
    query.setOption("no-skip", true);
    std::ostringstream discard;  // the listing is for this function, not for the user
    query.setCout(&discard);
    query.run();
    return RunRecord::listed;
}

}  // namespace

int main(int argc, char** argv) {
    doctest::Context context(argc, argv);
    // ctest registers the listed test cases: skipped ones must be listed too, or
    // they would vanish from its report instead of showing as skipped.
    if (lists_test_cases(argc, argv)) context.setOption("no-skip", true);
    const int result = context.run();
    if (context.shouldExit() || result != 0 || RunRecord::started > 0) return result;

    const std::vector<const doctest::TestCaseData*> selected = selected_test_cases(argc, argv);
    if (selected.empty()) {
        // A run that tests nothing must not pass: ctest would count a misregistered
        // name (e.g. one cut at a ';', which CMake lists split on) as a passed test.
        std::fprintf(stderr, "no test case matches the filters on the command line\n");
        return 1;
    }
    for (const doctest::TestCaseData* tc : selected)
        if (!tc->m_skip) return result;
    for (const doctest::TestCaseData* tc : selected)
        std::fprintf(stderr, "SKIPPED: %s (an optional part is missing from this build or CPU)\n",
                     tc->m_name);
    return kSkippedExitCode;
}
