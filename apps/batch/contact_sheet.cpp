// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/contact_sheet.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "geometry/output_file.h"

namespace fs = std::filesystem;

namespace surftex::batch {

namespace {

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1f s", s);
  else std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
}

constexpr const char* kStyle = R"(
body{font-family:system-ui,sans-serif;margin:1.5em;background:#f4f4f4;color:#222}
header h1{margin:0 0 .2em 0;font-size:1.5em}
header p{margin:0 0 1em 0;color:#555}
main{display:grid;grid-template-columns:repeat(auto-fill,minmax(300px,1fr));gap:1em}
article{background:#fff;border-radius:6px;padding:.8em;box-shadow:0 1px 3px rgba(0,0,0,.15);border-top:5px solid #3a3}
article.failed,article.interrupted{border-top-color:#c33}
article.not_run{border-top-color:#999}
article h2{font-size:1.05em;margin:0 0 .3em 0;word-break:break-all}
.status{display:inline-block;font-size:.8em;padding:.1em .5em;border-radius:3px;background:#3a3;color:#fff}
.failed .status,.interrupted .status{background:#c33}
.not_run .status{background:#999}
.time{font-size:.85em;color:#555;margin-left:.5em}
.error{color:#a00;font-family:monospace;font-size:.85em;white-space:pre-wrap;overflow-wrap:anywhere}
.images{display:flex;flex-wrap:wrap;gap:4px;margin:.5em 0}
.images a{flex:0 0 calc(33.3% - 3px)}
.images a:first-child{flex-basis:100%}
.images img{display:block;width:100%;height:auto;max-height:280px;object-fit:contain;background:#eee;border:1px solid #ddd}
.images a:not(:first-child) img{height:80px}
table{border-collapse:collapse;font-size:.85em;margin:.3em 0}
td{padding:.1em .6em .1em 0}td.v{text-align:right;font-variant-numeric:tabular-nums}
code{font-size:.75em;color:#444;overflow-wrap:anywhere}
.links{font-size:.8em}.links a{margin-right:.6em}
)";

// Marks each image loaded (data-loaded="1") or broken ("0") and counts them on
// <body data-images-ok=... data-images-broken=...>: read by headless checks.
constexpr const char* kScript = R"(
(function(){
  var imgs=document.images,ok=0,bad=0;
  function mark(img,good){if(img.dataset.loaded)return;img.dataset.loaded=good?"1":"0";if(good)ok++;else bad++;
    document.body.dataset.imagesOk=ok;document.body.dataset.imagesBroken=bad;}
  for(var i=0;i<imgs.length;i++){(function(img){
    if(img.complete){mark(img,img.naturalWidth>0);}else{
      img.addEventListener('load',function(){mark(img,img.naturalWidth>0);});
      img.addEventListener('error',function(){mark(img,false);});}})(imgs[i]);}
  document.body.dataset.imagesTotal=imgs.length;
})();
)";

void card_html(std::string& h, const SheetCard& c) {
  h += "<article class=\"card " + html_escape(c.status) + "\" data-status=\"" + html_escape(c.status) +
       "\" id=\"card-" + html_escape(c.title) + "\">\n";
  h += "<h2>" + html_escape(c.title) + "</h2>\n<p><span class=\"status\">" + html_escape(c.status) + "</span>";
  if (c.seconds >= 0) h += "<span class=\"time\">" + format_seconds(c.seconds) + "</span>";
  h += "</p>\n";
  if (!c.error.empty()) h += "<p class=\"error\">" + html_escape(c.error) + "</p>\n";
  if (!c.images.empty()) {
    h += "<div class=\"images\">";
    for (const std::string& img : c.images) {
      const std::string u = html_escape(relative_url(img));
      h += "<a href=\"" + u + "\"><img src=\"" + u + "\" alt=\"" + html_escape(img) + "\" title=\"" +
           html_escape(img) + "\"></a>";
    }
    h += "</div>\n";
  }
  if (!c.figures.empty()) {
    h += "<table>";
    for (const auto& [k, v] : c.figures)
      h += "<tr><td>" + html_escape(k) + "</td><td class=\"v\">" + html_escape(v) + "</td></tr>";
    h += "</table>\n";
  }
  if (!c.command.empty()) h += "<p><code>" + html_escape(c.command) + "</code></p>\n";
  if (!c.links.empty()) {
    h += "<p class=\"links\">";
    for (const std::string& l : c.links)
      h += "<a href=\"" + html_escape(relative_url(l)) + "\">" + html_escape(fs::path(l).filename().string()) + "</a> ";
    h += "</p>\n";
  }
  h += "</article>\n";
}

}  // namespace

std::string format_figure(double v) {
  char buf[64];
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string relative_url(const std::string& path) {
  std::string o;
  for (unsigned char c : path) {
    if (std::isalnum(c) || std::string("-_.~/").find(static_cast<char>(c)) != std::string::npos) {
      o += static_cast<char>(c);
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", c);
      o += buf;
    }
  }
  return o;
}

std::string contact_sheet_html(const ContactSheet& sheet) {
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<title>" + html_escape(sheet.title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n";
  h += "<header><h1>" + html_escape(sheet.title) + "</h1><p>" + html_escape(sheet.subtitle) + "</p></header>\n<main>\n";
  for (int pass = 0; pass < 2; ++pass)
    for (const SheetCard& c : sheet.cards)
      if ((c.status != "ok") == (pass == 0)) card_html(h, c);
  h += "</main>\n<script>" + std::string(kScript) + "</script>\n</body>\n</html>\n";
  return h;
}

void write_contact_sheet(const std::string& path, const ContactSheet& sheet) {
  write_file_atomic(path, contact_sheet_html(sheet), true);
}

ContactSheet batch_contact_sheet(const std::string& title, const std::vector<JobSummary>& jobs) {
  ContactSheet sheet;
  sheet.title = title;
  std::map<std::string, int> n;
  for (const JobSummary& j : jobs) {
    ++n[j.status];
    SheetCard c;
    c.title = j.name;
    c.status = j.status;
    c.command = j.command;
    c.error = j.error;
    c.seconds = j.seconds;
    for (const auto& [k, v] : j.figures) c.figures.emplace_back(k, format_figure(v));
    // The render large, up to three more images small; the rest as links.
    c.images.assign(j.images.begin(), j.images.begin() + std::min<std::size_t>(j.images.size(), 4));
    for (const std::string& o : j.outputs)
      if (std::find(c.images.begin(), c.images.end(), o) == c.images.end()) c.links.push_back(o);
    if (j.status != "ok" && !j.log.empty()) c.links.push_back(j.log);
    sheet.cards.push_back(std::move(c));
  }
  sheet.subtitle = std::to_string(jobs.size()) + " jobs: " + std::to_string(n["ok"]) + " ok, " +
                   std::to_string(n["failed"]) + " failed";
  if (n["interrupted"]) sheet.subtitle += ", " + std::to_string(n["interrupted"]) + " interrupted";
  if (n["not_run"]) sheet.subtitle += ", " + std::to_string(n["not_run"]) + " not run";
  return sheet;
}

namespace {

bool is_image_file(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e == ".png" || e == ".jpg" || e == ".jpeg";
}

// Strings anywhere in `j`, and its object keys (with their depth).
void collect_strings(const nlohmann::json& j, std::vector<std::string>& strings, std::vector<std::string>& keys) {
  if (j.is_string()) strings.push_back(j.get<std::string>());
  if (j.is_array())
    for (const auto& e : j) collect_strings(e, strings, keys);
  if (j.is_object())
    for (const auto& [k, v] : j.items()) {
      keys.push_back(k);
      collect_strings(v, strings, keys);
    }
}

// Numbers at the top two levels of a step's JSON, as figures.
void collect_figures(const nlohmann::json& j, const std::string& prefix, int depth,
                     std::vector<std::pair<std::string, std::string>>& out) {
  if (!j.is_object() || out.size() >= 8) return;
  for (const auto& [k, v] : j.items()) {
    if (k.rfind("seconds", 0) == 0) continue;
    if (v.is_number() && out.size() < 8) out.emplace_back(prefix + k, format_figure(v.get<double>()));
    else if (v.is_object() && depth < 1) collect_figures(v, prefix + k + " ", depth + 1, out);
  }
}

}  // namespace

void write_demo_contact_sheet(const std::string& dir, const nlohmann::json& report,
                              const std::vector<std::string>& files) {
  const fs::path root(dir);
  std::vector<std::string> images;  // relative to dir
  for (const std::string& f : files)
    if (is_image_file(fs::path(f))) images.push_back(fs::path(f).lexically_relative(root).generic_string());
  std::sort(images.begin(), images.end());
  std::set<std::string> claimed;
  ContactSheet sheet;
  sheet.title = "surftex demo";
  static const std::set<std::string> common_keys{"files", "outputs", "faces", "vertices", "size", "output_dir"};
  const nlohmann::json steps = report.contains("steps") ? report["steps"] : nlohmann::json::object();
  // Strong claims first (the step's folder, its name as prefix, a file its
  // JSON names), for every step, then weak ones (a part's name in the file name).
  std::map<std::string, std::string> owner;  // image -> step
  for (int strength = 0; strength < 2; ++strength)
    for (const auto& [name, step] : steps.items()) {
      std::vector<std::string> strings, keys;
      collect_strings(step, strings, keys);
      for (const std::string& img : images) {
        if (owner.count(img)) continue;
        const fs::path p(img);
        const std::string stem = p.stem().string(), first = p.begin()->string();
        bool mine = false;
        if (strength == 0) {
          mine = first == name || stem.rfind(name, 0) == 0;
          for (const std::string& s : strings)
            mine = mine || s == img || fs::path(s) == root / p || (p.parent_path().empty() && s == p.filename().string());
        } else {
          for (const std::string& k : keys)
            mine = mine || (k.size() >= 5 && !common_keys.count(k) && k.rfind("seconds", 0) != 0 &&
                            stem.find(k) != std::string::npos);
        }
        if (mine) owner[img] = name;
      }
    }
  // The report's "seconds": one number per step (and "total" once the shared keys are added).
  const nlohmann::json times = report.contains("seconds") && report["seconds"].is_object() ? report["seconds"]
                                                                                          : nlohmann::json::object();
  for (const auto& [name, step] : steps.items()) {
    SheetCard c;
    c.title = name;
    c.status = "ok";
    if (times.contains(name) && times[name].is_number()) c.seconds = times[name];
    for (const std::string& img : images)
      if (auto it = owner.find(img); it != owner.end() && it->second == name) c.images.push_back(img), claimed.insert(img);
    c.images = order_images(c.images);
    collect_figures(step, "", 0, c.figures);
    sheet.cards.push_back(std::move(c));
  }
  SheetCard rest;
  rest.title = "other images";
  rest.status = "ok";
  for (const std::string& img : images)
    if (!claimed.count(img)) rest.images.push_back(img);
  if (!rest.images.empty()) sheet.cards.push_back(rest);
  char sub[128];
  double total = times.contains("total") && times["total"].is_number() ? times["total"].get<double>() : -1;
  if (total < 0 && !times.empty()) {
    total = 0;
    for (const auto& [name, t] : times.items())
      if (t.is_number()) total += t.get<double>();
  }
  std::snprintf(sub, sizeof sub, "%zu steps, %zu images%s", steps.size(), images.size(),
                total >= 0 ? (", " + format_seconds(total)).c_str() : "");
  sheet.subtitle = sub;
  write_contact_sheet((root / "index.html").string(), sheet);
}

}  // namespace surftex::batch
