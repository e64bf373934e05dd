/* The step markers of the harness, included into NAME_test.c with -include. */
void hysid_step_begin(void);
void hysid_step_end(void);
#define HYSID_TEST_BEFORE_STEP() hysid_step_begin()
#define HYSID_TEST_AFTER_STEP() hysid_step_end()
