// Where the web part (web/: the page in dist/, the Node.js tools in tools/)
// is: $IPLAN_WEB_DIR, else <prefix>/share/iplan/web next to the installed
// executable, else the source tree's web/ folder.
#pragma once

#include <string>

namespace iplan::viewer {

/// The web folder; empty when none of the places has a built page
/// (dist/index.html).
std::string WebDir();

/// The Node.js interpreter: $IPLAN_NODE, else `node` on PATH; empty if none.
std::string NodeExecutable();

}  // namespace iplan::viewer
