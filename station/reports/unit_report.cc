#include "station/reports/unit_report.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "analysis/text.h"
#include "drivers/io/chart.h"
#include "station/reports/curve_chart.h"

namespace eol::station {
namespace {

// A4 in points; margins and line heights in points.
constexpr double kPageW = 595.28, kPageH = 841.89, kMargin = 42.0, kBottom = kPageH - 48.0;

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

cairo_status_t Append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

std::string Num(double v) {
  if (!std::isfinite(v)) return "-";
  return analysis::Significant(v, 5);
}

std::string LimitText(const analysis::Limit& l) {
  if (l.lo && l.hi) return Num(*l.lo) + " .. " + Num(*l.hi);
  if (l.lo) return ">= " + Num(*l.lo);
  if (l.hi) return "<= " + Num(*l.hi);
  return "none";
}

// Writes lines top to bottom, starting a new page when one is full.
class Writer {
 public:
  explicit Writer(cairo_t* cr) : cr_(cr) {}

  void Text(const std::string& s, double size, bool bold = false, double x = kMargin,
            io::Colour c = io::kChartBlack) {
    Room(size * 1.45);
    Show(s, size, bold, x, y_ + size, c);
    y_ += size * 1.45;
  }
  // Label and value in two columns; a long value wraps at the page's edge.
  void Field(const std::string& label, const std::string& value) {
    Room(14.0);
    Show(label, 9.5, true, kMargin, y_ + 10.0, io::kChartGrey);
    Wrapped(value, 10.0, kMargin + 120.0);
  }
  void Wrapped(const std::string& s, double size, double x) {
    std::string line;
    std::size_t at = 0;
    while (at <= s.size()) {
      std::size_t next = s.find(' ', at);
      if (next == std::string::npos) next = s.size();
      const std::string word = s.substr(at, next - at);
      const std::string candidate = line.empty() ? word : line + " " + word;
      if (!line.empty() && Width(candidate, size) > kPageW - kMargin - x) {
        Line(line, size, x);
        line = word;
      } else {
        line = candidate;
      }
      at = next + 1;
    }
    Line(line, size, x);
  }
  // Cells at fixed x offsets.
  void Row(const std::vector<std::pair<double, std::string>>& cells, double size, bool bold,
           io::Colour c = io::kChartBlack) {
    Room(size * 1.5);
    for (const auto& [x, s] : cells) Show(s, size, bold, kMargin + x, y_ + size, c);
    y_ += size * 1.5;
  }
  void Gap(double h) { y_ += h; }
  void Room(double h) {
    if (y_ + h <= kBottom) return;
    cairo_show_page(cr_);
    y_ = kMargin;
  }
  double y() const { return y_; }
  void NewPage() {
    cairo_show_page(cr_);
    y_ = kMargin;
  }

 private:
  void Line(const std::string& s, double size, double x) {
    Room(size * 1.4);
    Show(s, size, false, x, y_ + size, io::kChartBlack);
    y_ += size * 1.4;
  }
  void Font(double size, bool bold) {
    cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size);
  }
  double Width(const std::string& s, double size) {
    Font(size, false);
    cairo_text_extents_t e;
    cairo_text_extents(cr_, s.c_str(), &e);
    return e.x_advance;
  }
  void Show(const std::string& s, double size, bool bold, double x, double baseline, io::Colour c) {
    Font(size, bold);
    cairo_set_source_rgb(cr_, c.r, c.g, c.b);
    cairo_move_to(cr_, x, baseline);
    cairo_show_text(cr_, s.c_str());
  }

  cairo_t* cr_;
  double y_ = kMargin;
};

io::Colour VerdictColour(analysis::Outcome o) {
  switch (o) {
    case analysis::Outcome::kPass:
      return io::kChartGreen;
    case analysis::Outcome::kFail:
      return io::kChartRed;
    default:
      return io::kChartOrange;
  }
}

void Header(Writer& w, const UnitReport& r) {
  const db::TestRecord& t = r.test;
  w.Text("End-of-line test report", 11.0, false, kMargin, io::kChartGrey);
  w.Text("Serial " + t.serial, 20.0, true);
  w.Text(std::string("Verdict: ") + analysis::ToString(t.outcome), 26.0, true, kMargin,
         VerdictColour(t.outcome));
  w.Gap(6.0);
  const auto or_dash = [](const std::string& s) { return s.empty() ? std::string("-") : s; };
  w.Field("Test", "#" + std::to_string(t.id) +
                      (t.retest_of ? " (retest of #" + std::to_string(*t.retest_of) + ")" : ""));
  w.Field("Recipe", t.recipe_id + " version " + std::to_string(t.recipe_version));
  w.Field("Recipe SHA-256", t.recipe_hash);
  w.Field("Station", or_dash(t.station_id));
  w.Field("Operator", or_dash(t.work.operator_id));
  w.Field("Shift / order", or_dash(t.work.shift) + " / " + or_dash(t.work.order_number));
  w.Field("Started", or_dash(t.started_at));
  w.Field("Finished", or_dash(t.finished_at));
  w.Field("Tested by software", or_dash(t.software_version));
  w.Field("Report printed", r.printed_at + " by eol " + r.printed_by_software);
}

void Reasons(Writer& w, const db::TestRecord& t) {
  w.Gap(8.0);
  w.Text("Reasons", 13.0, true);
  if (t.reasons.empty()) w.Wrapped("none (every measurement within its limits)", 10.0, kMargin);
  for (const analysis::Reason& reason : t.reasons)
    w.Wrapped(std::string("- ") + analysis::ToString(reason.code) + ": " + reason.text, 10.0,
              kMargin);
}

void Measurements(Writer& w, const db::TestRecord& t) {
  w.Gap(8.0);
  w.Text("Measurements", 13.0, true);
  const std::vector<double> x = {0.0, 210.0, 290.0, 330.0, 470.0};
  w.Row({{x[0], "name"}, {x[1], "value"}, {x[2], "unit"}, {x[3], "limits"}, {x[4], "outcome"}}, 9.0,
        true, io::kChartGrey);
  for (const analysis::Measurement& m : t.measurements) {
    const std::string outcome =
        std::string(analysis::ToString(m.outcome)) + (m.marginal ? " (marginal)" : "");
    const io::Colour c =
        m.outcome == analysis::MeasurementOutcome::kFail ? io::kChartRed : io::kChartBlack;
    w.Row({{x[0], m.name},
           {x[1], Num(m.value)},
           {x[2], m.unit},
           {x[3], LimitText(m.limit)},
           {x[4], outcome}},
          9.0, false, c);
  }
  if (t.measurements.empty()) w.Wrapped("no measurement stored", 10.0, kMargin);
}

void Teardowns(Writer& w, const UnitReport& r) {
  w.Gap(8.0);
  w.Text("Teardown findings", 13.0, true);
  if (r.teardowns.empty()) {
    w.Wrapped("none recorded", 10.0, kMargin);
    return;
  }
  for (const db::TeardownEntry& e : r.teardowns)
    w.Wrapped(e.at + "  " + db::ToString(e.found) + " (judged test #" +
                  (e.test_id ? std::to_string(*e.test_id) : "-") + ") by " + e.by +
                  (e.corrects ? ", corrects #" + std::to_string(*e.corrects) : "") +
                  (e.note.empty() ? "" : ": " + e.note),
              10.0, kMargin);
  w.Wrapped("current: " + std::string(db::ToString(r.teardowns.back().found)), 10.0, kMargin);
}

const db::Curve* FindCurve(const db::TestRecord& t, const std::string& name) {
  for (const db::Curve& c : t.curves)
    if (c.name == name) return &c;
  return nullptr;
}

std::vector<std::complex<double>> Values(const db::Curve& c) {
  std::vector<std::complex<double>> v;
  for (std::size_t i = 0; i < c.re.size() && i < c.im.size(); ++i) v.emplace_back(c.re[i], c.im[i]);
  return v;
}

// The stored curve as `eol query --plot` draws it, scaled to the page's width.
void CurvePage(Writer& w, cairo_t* cr, const UnitReport& r) {
  const db::TestRecord& t = r.test;
  const db::Curve* measured = FindCurve(t, "impedance");
  w.NewPage();
  w.Text("Impedance curve with limits", 13.0, true);
  if (!measured) {
    w.Wrapped("This test stored no impedance curve (verdict " +
                  std::string(analysis::ToString(t.outcome)) + ").",
              10.0, kMargin);
    return;
  }
  CurvePlot p;
  p.title = t.serial + " test #" + std::to_string(t.id) + " - " + t.recipe_id + " v" +
            std::to_string(t.recipe_version) + ": " + analysis::ToString(t.outcome);
  p.freq_hz = measured->freq_hz;
  p.measured = Values(*measured);
  if (const db::Curve* model = FindCurve(t, "model")) {
    p.model_freq_hz = model->freq_hz;
    p.model = Values(*model);
  }
  for (const analysis::Measurement& m : t.measurements)
    if (m.name == "resonance_f_hz") {
      p.resonance_window = m.limit;
      if (std::isfinite(m.value)) p.f0_hz = m.value;
    }
  p.masks = r.masks;
  if (!r.masks_note.empty()) p.notes.push_back(r.masks_note);
  const io::Chart chart = CurveChart(p);
  const double scale = (kPageW - 2.0 * kMargin) / io::ChartWidth(chart);
  cairo_save(cr);
  cairo_translate(cr, kMargin, w.y() + 4.0);
  cairo_scale(cr, scale, scale);
  io::DrawChart(cr, chart);
  cairo_restore(cr);
}

}  // namespace

std::string RenderUnitReportPdf(const UnitReport& r) {
  std::string pdf;
  std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
      cairo_pdf_surface_create_for_stream(Append, &pdf, kPageW, kPageH));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(std::string("cairo PDF surface: ") +
                             cairo_status_to_string(cairo_surface_status(surface.get())));
  const std::string title = "EOL unit report " + r.test.serial;
  cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, title.c_str());
  cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR,
                                 ("eol " + r.printed_by_software).c_str());
  {
    std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
    Writer w(cr.get());
    Header(w, r);
    Reasons(w, r.test);
    Measurements(w, r.test);
    Teardowns(w, r);
    CurvePage(w, cr.get(), r);
    cairo_show_page(cr.get());
    if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error(std::string("cairo drawing the report: ") +
                               cairo_status_to_string(cairo_status(cr.get())));
  }
  cairo_surface_finish(surface.get());
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(std::string("cairo PDF output: ") +
                             cairo_status_to_string(cairo_surface_status(surface.get())));
  return pdf;
}

UnitReport LoadUnitReport(db::Store& store, const std::string& serial, std::int64_t test_id,
                          const std::string& recipe_masks_hash,
                          const std::vector<analysis::CurveMask>& recipe_masks) {
  UnitReport r;
  std::optional<db::TestRecord> t =
      test_id != 0 ? store.Test(test_id, true) : store.LatestOfSerial(serial);
  if (!t || t->serial != serial)
    throw std::out_of_range(test_id != 0
                                ? serial + " has no finished test #" + std::to_string(test_id)
                                : serial + " has no finished test in " + store.path());
  r.test = std::move(*t);
  r.teardowns = store.TeardownsOfSerial(serial);
  if (recipe_masks_hash.empty())
    r.masks_note = "masks not drawn: no recipe given for this test";
  else if (recipe_masks_hash != r.test.recipe_hash)
    r.masks_note = "masks not drawn: the recipe given is not this test's";
  else
    r.masks = recipe_masks;
  return r;
}

}  // namespace eol::station
