// The seventh model's trained initial states (trained_states.h); the table itself is generated.
#include "coding/hierarchy/trained_states.h"

#include "coding/hierarchy/context_mixing.h"

namespace amc {

BitModel trained_state(char c, int window_log2) {
    BitModel m(window_log2);
    if (c == kUntrainedSlot) return m;
    m.p = uint32_t(mixing::squash(128 * trained_state_of(c))) << 20;
    m.n = uint16_t(kTrainedCount);
    return m;
}

#include "coding/hierarchy/trained_states_table.inc"

}  // namespace amc
