#include "studies/version.hpp"

#include "bbm_version.hpp" // generated at every build (cmake/write_version.cmake)

namespace bbm::studies {

const char* version_text() { return BBM_VERSION_TEXT; }

} // namespace bbm::studies
