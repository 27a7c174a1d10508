// Where the program finds its shipped files when no option names one: never a path of the
// machine it was built on. Candidates, first existing wins:
//   1. the working directory (a checkout, or a copy of its recipes/ and station/web/),
//   2. the station's state directory /var/lib/eol/ (the recipes in use; recipes only),
//   3. <prefix>/share/eol/, <prefix> being the folder above the running program's own
//      (/usr/bin/eol -> /usr/share/eol/), as the package installs them.
#pragma once

#include <string>

namespace eol::station {

// <prefix>/share/eol of the running program ("" when /proc/self/exe cannot be read).
std::string InstalledDataDir();

// The recipe `name` (e.g. "pmsm-10pole.json"): recipes/<name> in the working directory,
// /var/lib/eol/recipes/<name>, <prefix>/share/eol/recipes/<name>. When none exists, the
// working-directory path, so the error that follows names what was looked for.
std::string DefaultRecipePath(const std::string& name = "pmsm-10pole.json");

// The operator page: station/web/dist or station/web in the working directory, else
// <prefix>/share/eol/web; "" when none exists.
std::string DefaultWebRoot();

// The SciPy peer of the fit bench: deploy/bench/fit_pipeline_scipy.py in the working
// directory, else <prefix>/share/eol/bench/fit_pipeline_scipy.py.
std::string DefaultScipyPipelineScript();

// One line for --help: where the defaults above are looked for.
inline constexpr const char* kDefaultsSearchHelp =
    "defaults are looked for in the working directory, then /var/lib/eol (recipes), then "
    "<prefix>/share/eol of the installed program";

}  // namespace eol::station
