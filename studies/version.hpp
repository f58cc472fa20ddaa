// bbm studies: the version of bbm and the commit it was built from, as outputs
// record it (summary.json's bbm_version).
#pragma once

namespace bbm::studies {

/// "0.1.0 (<commit>)", "-dirty" after the commit if the tree had changes.
const char* version_text();

} // namespace bbm::studies
