// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A static contact sheet (issue 20, items 3 and 4): one HTML page, one card per
// job (or demo step) with its images, figures, time and status, failed cards
// first. Links are relative to the page and the page needs no server, no
// network and no script to show (a small inline script only marks each image
// loaded or broken, for checks in a headless browser).
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "batch/batch_summary.h"

namespace surftex::batch {

struct SheetCard {
  std::string title;
  std::string status;   ///< "ok", "failed", "interrupted", "not_run"
  std::string command;  ///< shown in monospace; may be empty
  std::string error;
  double seconds = -1;  ///< -1: not shown
  std::vector<std::pair<std::string, std::string>> figures;  ///< label, formatted value
  std::vector<std::string> images;  ///< paths relative to the page
  std::vector<std::string> links;   ///< paths relative to the page
};

struct ContactSheet {
  std::string title;
  std::string subtitle;
  std::vector<SheetCard> cards;
};

/// A number for a card: integers as integers, others with 4 significant digits.
std::string format_figure(double v);
/// A relative path as a URL: each segment percent-encoded, '/' kept.
std::string relative_url(const std::string& path);

/// The page; cards that are not "ok" come first, each group in given order.
std::string contact_sheet_html(const ContactSheet& sheet);
/// Writes the page atomically to `path`.
void write_contact_sheet(const std::string& path, const ContactSheet& sheet);

/// A batch's sheet from its job summaries (paths relative to OUT).
ContactSheet batch_contact_sheet(const std::string& title, const std::vector<JobSummary>& jobs);

/// The demo's sheet, DIR/index.html, from the report `surftex demo` writes
/// ({"steps": {NAME: {...}}}): one card per step with the images it made
/// (files its JSON names, its subfolder DIR/NAME/, files named after the step
/// or after one of its parts), and a last card with images no step claims.
/// `files`: the run's outputs (paths under DIR; they may still be staged,
/// geometry/output_file.h), of which the images are shown.
void write_demo_contact_sheet(const std::string& dir, const nlohmann::json& report,
                              const std::vector<std::string>& files);

}  // namespace surftex::batch
