/* startup.c: a minimal Cortex-M start for qemu's mps2-an386 (Cortex-M4F):
 * the vector table, the FPU switched on, .data copied and .bss zeroed, then
 * main; emb_write and the exit go through semihosting (qemu -semihosting-config
 * enable=on).  On a real board use the vendor's startup instead. */
extern unsigned long _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void Reset_Handler(void);
void emb_write(const char *s);

static void halt(void) {
  for (;;) {}
}

__attribute__((section(".isr_vector"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(&_estack), Reset_Handler, halt, halt, halt, halt, halt, 0, 0, 0, 0, halt, halt, 0, halt, halt};

static int semihost(int op, const void *arg) {
  register int r0 __asm__("r0") = op;
  register const void *r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

void emb_write(const char *s) { semihost(0x04, s); } /* SYS_WRITE0 */

void Reset_Handler(void) {
  *(volatile unsigned long *)0xE000ED88UL |= 0xFUL << 20; /* CPACR: full access to CP10, CP11 */
  __asm__ volatile("dsb\n\tisb");
  unsigned long *src = &_sidata, *dst = &_sdata;
  while (dst < &_edata) *dst++ = *src++;
  for (dst = &_sbss; dst < &_ebss;) *dst++ = 0;
  int rc = main();
  unsigned long block[2] = {0x20026UL, (unsigned long)rc}; /* ADP_Stopped_ApplicationExit */
  semihost(0x20, block); /* SYS_EXIT_EXTENDED: qemu exits with rc */
  halt();
}
