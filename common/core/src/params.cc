#include "iplan/core/params.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace iplan::core {
namespace {

// Quoted when YAML would read the plain text as something else (a number, a
// boolean, null) or it holds characters with a meaning in YAML.
std::string QuoteIfNeeded(const std::string& s) {
  bool plain = !s.empty() && s.find_first_of(":#[]{},&*!|>'\"%@`") == std::string::npos &&
               s.front() != ' ' && s.back() != ' ' && s.front() != '-';
  if (plain) {
    try {
      const YAML::Node n = YAML::Load(s);
      double d = 0;
      plain = n.IsScalar() && n.Scalar() == s && !YAML::convert<double>::decode(n, d) && s != "true" &&
              s != "false" && s != "null" && s != "~";
    } catch (const YAML::Exception&) {
      plain = false;
    }
  }
  if (plain) return s;
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

template <class T>
std::string List(const std::vector<T>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + ParamText(v[i]);
  return s + "]";
}

}  // namespace

std::string ParamText(bool v) { return v ? "true" : "false"; }
std::string ParamText(int v) { return std::to_string(v); }
std::string ParamText(std::uint64_t v) { return std::to_string(v); }

std::string ParamText(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? ".nan" : (v > 0 ? ".inf" : "-.inf");
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  // "1" would read back as an integer in the docs; keep it a number with a point.
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string ParamText(const std::string& v) { return QuoteIfNeeded(v); }
std::string ParamText(const std::vector<double>& v) { return List(v); }
std::string ParamText(const std::vector<std::string>& v) { return List(v); }

std::string ParamText(const std::vector<std::pair<std::string, std::string>>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    s += (i ? ", [" : "[") + ParamText(v[i].first) + ", " + ParamText(v[i].second) + "]";
  }
  return s + "]";
}

std::string ParamsMarkdownTable(const std::vector<ParamDoc>& docs) {
  std::string s = "| key | default | meaning |\n|---|---|---|\n";
  for (const ParamDoc& d : docs) {
    std::string doc = d.doc;
    for (std::size_t p = doc.find('|'); p != std::string::npos; p = doc.find('|', p + 2)) doc.replace(p, 1, "\\|");
    s += "| `" + d.key + "` | `" + d.value + "` | " + doc + " |\n";
  }
  return s;
}

std::string CheckDocumentedDefaults(const std::string& doc_path, const std::vector<ParamDoc>& docs) {
  std::ifstream in(doc_path);
  if (!in) return "cannot read " + doc_path;
  std::stringstream text;
  text << in.rdbuf();
  const std::string table = ParamsMarkdownTable(docs);
  if (text.str().find(table) != std::string::npos) return "";
  return doc_path + " does not hold the declared defaults (regenerate it with `iplan config defaults NAME "
                    "--markdown`); expected the table\n" + table;
}

}  // namespace iplan::core
