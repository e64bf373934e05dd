/* Calls the exported model's test program (HYSID_TEST_RUN, e.g. -DHYSID_TEST_RUN=pi_test_run)
 * and reports PASS or FAIL through semihosting. Each step is framed by hysid_step_begin and
 * hysid_step_end (markers.h), whose addresses run.py finds in the instruction trace. */
#include "markers.h"

void host_print(const char *text);
int HYSID_TEST_RUN(void);
int main(void);

__attribute__((noinline)) void hysid_step_begin(void) { __asm__ volatile("" ::: "memory"); }
__attribute__((noinline)) void hysid_step_end(void) { __asm__ volatile("" ::: "memory"); }

int main(void) {
    /* An empty frame first: run.py subtracts its count (the markers' own instructions). */
    hysid_step_begin();
    hysid_step_end();
    const int failures = HYSID_TEST_RUN();
    host_print(failures == 0 ? "PASS\n" : "FAIL\n");
    return failures == 0 ? 0 : 1;
}
