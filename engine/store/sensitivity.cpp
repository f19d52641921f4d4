// ResultsWriter::write_sensitivity / ResultsReader::read_sensitivity: /sensitivity, the Sobol'
// indices of a file's Saltelli designs (see store.hpp, FORMAT.md).
#include "store/reader_impl.hpp"
#include "store/store.hpp"
#include "store/table_group.hpp"

namespace ks::store {
using namespace detail;

namespace {
constexpr const char* kSensitivityGroup = "sensitivity";
}  // namespace

void ResultsWriter::write_sensitivity(const SensitivityTable& t) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  Hid g = replace_group(m, kSensitivityGroup,
                 "first-order and total Sobol' indices of the Saltelli designs (/designs): each row one factor of "
                 "one metric at one combination of its block's other dimensions (Saltelli 2010's centred "
                 "first-order estimator, Jansen's total one, over the sample rows whose runs all have the kind's "
                 "good status; percentile bootstrap intervals)");
  TableOut o{m, "/sensitivity"};
  write_i64_attr(g, "bootstrap", t.bootstrap);
  o.f64_attr(g, "confidence", t.confidence);
  write_i64_attr(g, "seed", t.seed);
  const auto& rows = t.rows;
  o.str(g, "block", column_of(rows, [](const auto& r) { return r.block; }), "the design's block");
  o.str(g, "metric", column_of(rows, [](const auto& r) { return r.metric; }), "the /runs metric");
  o.i64(g, "combination", column_of(rows, [](const auto& r) { return r.combination; }),
        "the combination of the block's other dimensions, in run order (0 when it has none)");
  o.str(g, "factor", column_of(rows, [](const auto& r) { return r.factor; }), "the factor (an axis of the design)");
  o.i64(g, "factor_index", column_of(rows, [](const auto& r) { return r.factor_index; }),
        "its position in /designs/<block>@factors");
  o.f64(g, "first", column_of(rows, [](const auto& r) { return r.first; }), 0, "", "first-order index S_i");
  o.f64(g, "first_lo", column_of(rows, [](const auto& r) { return r.first_lo; }), 0, "", "S_i's bootstrap interval, lower end");
  o.f64(g, "first_hi", column_of(rows, [](const auto& r) { return r.first_hi; }), 0, "", "S_i's bootstrap interval, upper end");
  o.f64(g, "total", column_of(rows, [](const auto& r) { return r.total; }), 0, "", "total index S_Ti");
  o.f64(g, "total_lo", column_of(rows, [](const auto& r) { return r.total_lo; }), 0, "", "S_Ti's bootstrap interval, lower end");
  o.f64(g, "total_hi", column_of(rows, [](const auto& r) { return r.total_hi; }), 0, "", "S_Ti's bootstrap interval, upper end");
  o.f64(g, "variance", column_of(rows, [](const auto& r) { return r.variance; }), 0, "",
        "the metric's variance over the sample rows A and B (the metric's unit squared)");
  o.i64(g, "samples", column_of(rows, [](const auto& r) { return r.samples; }), "sample rows used");
  o.i64(g, "dropped", column_of(rows, [](const auto& r) { return r.dropped; }),
        "sample rows left out: a run of the row failed or is not done");
  o.dimensions(g, "sensitivity_row");
  m.do_flush();
}

SensitivityTable ResultsReader::read_sensitivity() const {
  QuietHdf5 quiet;
  SensitivityTable t;
  const std::optional<TableIn> table = TableIn::open(impl_->file, impl_->path, kSensitivityGroup, "block");
  if (!table) return t;
  const TableIn& in = *table;
  t.bootstrap = in.attr_i64("bootstrap", t.bootstrap);
  t.confidence = in.attr_f64("confidence", t.confidence);
  t.seed = in.attr_i64("seed", t.seed);
  const auto block = in.str("block"), metric = in.str("metric"), factor = in.str("factor");
  const auto combination = in.i64("combination"), factor_index = in.i64("factor_index"), samples = in.i64("samples"),
             dropped = in.i64("dropped");
  const auto first = in.f64("first"), first_lo = in.f64("first_lo"), first_hi = in.f64("first_hi"),
             total = in.f64("total"), total_lo = in.f64("total_lo"), total_hi = in.f64("total_hi"),
             variance = in.f64("variance");
  for (std::size_t i = 0; i < in.rows(); ++i) {
    SensitivityRow r;
    r.block = block[i], r.metric = metric[i], r.combination = combination[i], r.factor = factor[i];
    r.factor_index = factor_index[i];
    r.first = first[i], r.first_lo = first_lo[i], r.first_hi = first_hi[i];
    r.total = total[i], r.total_lo = total_lo[i], r.total_hi = total_hi[i];
    r.variance = variance[i], r.samples = samples[i], r.dropped = dropped[i];
    t.rows.push_back(std::move(r));
  }
  return t;
}

}  // namespace ks::store
