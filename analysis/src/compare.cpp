#include "compare.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <toml.hpp>

namespace cda {
namespace {

double as_number(const toml::value& v, const std::string& what) {
  if (v.is_floating()) return v.as_floating();
  if (v.is_integer()) return static_cast<double>(v.as_integer());
  throw InputError(fmt::format("{} is not a number", what));
}

}  // namespace

FitFile read_fit_toml(const std::string& path) {
  FitFile f;
  f.path = path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(fmt::format("fit file '{}' does not exist", path));
  refuse_folder(path);
  std::istringstream text(toml_text(path));
  toml::value root;
  try {
    root = toml::parse(text, path);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("fit file '{}' does not parse as TOML: {}", path, e.what()));
  }
  // toml11's default table is unordered; the names arrays keep the file's
  // parameter order, and models are sorted by name.
  std::vector<std::string> models;
  for (const auto& [name, v] : root.as_table())
    if (v.is_table()) models.push_back(name);
  std::sort(models.begin(), models.end());
  for (const auto& name : models) {
    const auto& m = root.at(name);
    // A fit written as undetermined (fits_to_toml's refused fits) has no
    // parameters: read as missing, so that comparing against it FAILs.
    if (m.contains("determined") && m.at("determined").is_boolean() && !m.at("determined").as_boolean() &&
        !m.contains("params"))
      continue;
    FitRecord r;
    if (m.contains("converged") && m.at("converged").is_boolean()) r.converged = m.at("converged").as_boolean();
    if (m.contains("chi2") && m.at("chi2").is_floating()) r.chi2 = m.at("chi2").as_floating();
    if (m.contains("dof") && m.at("dof").is_integer()) r.dof = static_cast<int>(m.at("dof").as_integer());
    if (!m.contains("params") || !m.at("params").is_table())
      throw InputError(fmt::format("fit file '{}': [{}] has no [{}.params] tables", path, name, name));
    std::vector<std::string> names;
    if (m.contains("names") && m.at("names").is_array())
      for (const auto& n : m.at("names").as_array())
        if (n.is_string()) names.push_back(n.as_string());
    for (const auto& [pn, pv] : m.at("params").as_table())
      if (std::find(names.begin(), names.end(), pn) == names.end()) names.push_back(pn);
    for (const auto& pn : names) {
      const std::string where = fmt::format("fit file '{}': [{}.params.{}]", path, name, pn);
      if (!m.at("params").contains(pn)) throw InputError(where + " is missing (listed in names)");
      const auto& pv = m.at("params").at(pn);
      if (!pv.is_table() || !pv.contains("value") || !pv.contains("error"))
        throw InputError(where + " needs both value and error");
      r.params[pn] = {as_number(pv.at("value"), where + " value"), as_number(pv.at("error"), where + " error")};
    }
    r.order = names;
    f.order.push_back(name);
    f.models[name] = std::move(r);
  }
  if (f.models.empty()) throw InputError(fmt::format("fit file '{}' holds no fit table", path));
  return f;
}

bool Comparison::ok() const { return failures() == 0; }
std::size_t Comparison::failures() const {
  std::size_t n = 0;
  for (const auto& r : rows) n += !r.ok;
  return n;
}

Comparison compare_fits(const FitFile& ref, const FitFile& now, double tol_sigma, double tol_rel) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Comparison c;
  for (const auto& mname : ref.order) {
    const auto& rm = ref.models.at(mname);
    const auto it = now.models.find(mname);
    for (const auto& pn : rm.order) {
      ComparisonRow row;
      row.model = mname;
      row.param = pn;
      row.ref = rm.params.at(pn);
      if (it == now.models.end()) {
        row.in_new = row.ok = false;
        row.note = fmt::format("model [{}] missing from {}", mname, now.path);
      } else if (!it->second.params.count(pn)) {
        row.in_new = row.ok = false;
        row.note = fmt::format("parameter missing from [{}] of {}", mname, now.path);
      } else {
        row.now = it->second.params.at(pn);
        const double d = std::abs(row.now.value - row.ref.value);
        const double s = std::hypot(row.ref.error, row.now.error);
        row.sigmas = d == 0 ? 0 : (s > 0 ? d / s : inf);
        row.relative = d == 0 ? 0 : (row.ref.value != 0 ? d / std::abs(row.ref.value) : inf);
        if (!std::isfinite(row.now.value) || !std::isfinite(row.now.error) || !std::isfinite(row.ref.value) ||
            !std::isfinite(row.ref.error)) {
          row.ok = false;
          row.note = "non-finite value or error";
        } else if (row.sigmas > tol_sigma && row.relative > tol_rel) {
          row.ok = false;
          row.note = "shifted";
        } else if (rm.converged && !it->second.converged) {
          row.ok = false;
          row.note = "new fit not converged";
        }
      }
      c.rows.push_back(row);
    }
    if (it == now.models.end()) continue;
    for (const auto& pn : it->second.order)
      if (!rm.params.count(pn)) {
        ComparisonRow row;
        row.model = mname;
        row.param = pn;
        row.in_reference = false;
        row.now = it->second.params.at(pn);
        row.note = "only in the new file";
        c.rows.push_back(row);
      }
  }
  for (const auto& mname : now.order)
    if (!ref.models.count(mname)) {
      ComparisonRow row;
      row.model = mname;
      row.param = "*";
      row.in_reference = false;
      row.note = "model only in the new file";
      c.rows.push_back(row);
    }
  return c;
}

std::string format_comparison(const Comparison& c, double tol_sigma, double tol_rel) {
  std::string s = fmt::format("{:<16} {:<12} {:>26} {:>26} {:>9} {:>10}  {}\n", "model", "parameter",
                              "reference +- err", "new +- err", "|d|/sigma", "|d|/|ref|", "status");
  auto pm = [](const FitParam& p) { return fmt::format("{:.6g} +- {:.2g}", p.value, p.error); };
  for (const auto& r : c.rows) {
    const std::string a = r.in_reference ? pm(r.ref) : "-";
    const std::string b = r.in_new && r.param != "*" ? pm(r.now) : "-";
    const bool both = r.in_reference && r.in_new;
    s += fmt::format("{:<16} {:<12} {:>26} {:>26} {:>9} {:>10}  {}{}\n", r.model, r.param, a, b,
                     both ? fmt::format("{:.2f}", r.sigmas) : "-",
                     both ? fmt::format("{:.2e}", r.relative) : "-", r.ok ? "OK" : "FAIL",
                     r.note.empty() ? "" : " (" + r.note + ")");
  }
  s += fmt::format("rule: FAIL when |d| > {} sigma_combined AND |d| > {} |ref|; "
                   "sigma_combined = sqrt(err_ref^2 + err_new^2)\n",
                   tol_sigma, tol_rel);
  s += c.ok() ? fmt::format("compare-fits: OK ({} parameters)\n", c.rows.size())
              : fmt::format("compare-fits: {} FAIL of {} rows\n", c.failures(), c.rows.size());
  return s;
}

}  // namespace cda
