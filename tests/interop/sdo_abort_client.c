/* SDO client for the interop tests: SOEM's own ec_SDOwrite / ec_SDOread (v1.4.0) or
 * ecx_SDOwrite / ecx_SDOread (v2.0.0, built with -DSOEM_V2) against one slave, printing what
 * SOEM returns and every error SOEM records, so the test can tell a refused access from one
 * SOEM took for success. A separate program: built against SOEM's libsoem.a by the ctest
 * fixture (build_soem.sh), never linked into ecsim.
 *
 * usage: sdo_abort_client IFNAME SLAVE read INDEX SUB
 *        sdo_abort_client IFNAME SLAVE write INDEX SUB VALUE   (4-byte expedited write)
 * prints: "slaves N state S", then "result R" (the working counter SOEM returns: 0 = failed),
 *         "data 0xXXXXXXXX size N" after a successful read, and one line per recorded error:
 *         "error type T index 0xIIII:SS code 0xCCCCCCCC" (type 0 = SDO abort, SOEM's
 *         EC_ERR_TYPE_SDO_ERROR; 3 = packet error, whose code is SOEM's own number).
 * exit: 0 when the request was made, 2 on bad arguments, 3 when no slave was found.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef SOEM_V2
#include "soem/soem.h"
static ecx_contextt ctx;
#define SLAVECOUNT (ctx.slavecount)
#define SLAVESTATE(i) (ctx.slavelist[i].state)
#define INIT(ifname) ecx_init(&ctx, ifname)
#define CONFIG_INIT() ecx_config_init(&ctx)
#define STATECHECK(s, st) ecx_statecheck(&ctx, s, st, EC_TIMEOUTSTATE)
#define SDOWRITE(s, i, sub, n, p) ecx_SDOwrite(&ctx, s, i, sub, FALSE, n, p, EC_TIMEOUTRXM)
#define SDOREAD(s, i, sub, n, p) ecx_SDOread(&ctx, s, i, sub, FALSE, n, p, EC_TIMEOUTRXM)
#define POPERROR(e) ecx_poperror(&ctx, e)
#define CLOSE() ecx_close(&ctx)
#else
#include "ethercat.h"
#define SLAVECOUNT (ec_slavecount)
#define SLAVESTATE(i) (ec_slave[i].state)
#define INIT(ifname) ec_init(ifname)
#define CONFIG_INIT() ec_config_init(FALSE)
#define STATECHECK(s, st) ec_statecheck(s, st, EC_TIMEOUTSTATE)
#define SDOWRITE(s, i, sub, n, p) ec_SDOwrite(s, i, sub, FALSE, n, p, EC_TIMEOUTRXM)
#define SDOREAD(s, i, sub, n, p) ec_SDOread(s, i, sub, FALSE, n, p, EC_TIMEOUTRXM)
#define POPERROR(e) ec_poperror(e)
#define CLOSE() ec_close()
#endif

int main(int argc, char *argv[])
{
   if (argc < 6 || (strcmp(argv[3], "read") != 0 && strcmp(argv[3], "write") != 0) ||
       (strcmp(argv[3], "write") == 0 && argc < 7))
   {
      fprintf(stderr, "usage: %s IFNAME SLAVE read|write INDEX SUB [VALUE]\n", argv[0]);
      return 2;
   }
   const int slave = atoi(argv[2]);
   const int write = strcmp(argv[3], "write") == 0;
   const uint16 index = (uint16)strtoul(argv[4], NULL, 0);
   const uint8 sub = (uint8)strtoul(argv[5], NULL, 0);
   if (!INIT(argv[1]))
   {
      printf("init on %s failed\n", argv[1]);
      return 3;
   }
   if (CONFIG_INIT() <= 0 || slave < 1 || slave > SLAVECOUNT)
   {
      printf("slaves %d: slave %d not found\n", SLAVECOUNT, slave);
      CLOSE();
      return 3;
   }
   /* config_init requests PREOP; SDOs need the mailbox, so wait for it. */
   STATECHECK(slave, EC_STATE_PRE_OP);
   printf("slaves %d state %d\n", SLAVECOUNT, SLAVESTATE(slave));
   int result;
   uint8 data[4] = {0, 0, 0, 0};
   int size = sizeof(data);
   if (write)
   {
      const uint32 value = (uint32)strtoul(argv[6], NULL, 0);
      data[0] = (uint8)value;
      data[1] = (uint8)(value >> 8);
      data[2] = (uint8)(value >> 16);
      data[3] = (uint8)(value >> 24);
      result = SDOWRITE(slave, index, sub, size, data);
   }
   else
   {
      result = SDOREAD(slave, index, sub, &size, data);
   }
   printf("result %d\n", result);
   if (!write && result > 0)
   {
      printf("data 0x%02x%02x%02x%02x size %d\n", data[3], data[2], data[1], data[0], size);
   }
   ec_errort error;
   while (POPERROR(&error))
   {
      printf("error type %d index 0x%04x:%02x code 0x%08x\n", (int)error.Etype, error.Index,
             error.SubIdx, (unsigned)error.AbortCode);
   }
   CLOSE();
   return 0;
}
