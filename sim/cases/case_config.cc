#include "sim/cases/case_config.h"

#include <sstream>
#include <vector>

#include "sim/mujoco_util.h"

namespace vmh::sim {

CaseConfig CaseConfig::from_model(const mjModel* m, const std::string& source,
                                  const std::vector<std::string>& overrides) {
  // the model's custom fields, as text: numbers to full precision
  std::vector<CustomField> fields;
  for (int i = 0; i < m->nnumeric; ++i) {
    if (m->numeric_size[i] == 0) continue;  // no values: as if not given
    CustomField f;
    f.name = m->names + m->name_numericadr[i];
    std::ostringstream s;
    s.precision(17);
    for (int k = 0; k < m->numeric_size[i]; ++k) {
      s << m->numeric_data[m->numeric_adr[i] + k] << ' ';
    }
    f.value = s.str();
    fields.push_back(std::move(f));
  }
  for (int i = 0; i < m->ntext; ++i) {
    fields.push_back({m->names + m->name_textadr[i], true,
                      m->text_data + m->text_adr[i]});
  }
  try {
    CaseConfig c;
    static_cast<CaseParams&>(c) = case_params_from_fields(fields, source, overrides);
    return c;
  } catch (const ParamError& e) {
    throw SimError(e.what());
  }
}

}  // namespace vmh::sim
