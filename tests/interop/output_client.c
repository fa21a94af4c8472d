/* An external master for the control-socket test (docs/control.md): SOEM v1.4.0 brings the
 * network to OP and writes one byte pattern to the first output byte of one slave every cycle
 * (1 ms), so the test can read with `ecsim ctl get` what a master that is not ours wrote.
 * A separate program: built against SOEM's libsoem.a by the ctest fixture (build_soem.sh),
 * never linked into ecsim.
 *
 * usage: output_client IFNAME SLAVE VALUE SECONDS
 * prints: "slaves N", then "op outputs 0xVV" once every slave is in OP (or "not in OP: slave
 *         S state 0xSS" lines and exit 4), "done cycles C wkc-errors E" at the end.
 * exit: 0 after SECONDS of cycles, 2 on bad arguments, 3 when no slave was found.
 */
#include <stdio.h>
#include <stdlib.h>

#include "ethercat.h"

static char io_map[4096];

int main(int argc, char *argv[])
{
   if (argc != 5)
   {
      fprintf(stderr, "usage: %s IFNAME SLAVE VALUE SECONDS\n", argv[0]);
      return 2;
   }
   const int slave = atoi(argv[2]);
   const uint8 value = (uint8)strtoul(argv[3], NULL, 0);
   const int seconds = atoi(argv[4]);
   if (!ec_init(argv[1]))
   {
      printf("init on %s failed\n", argv[1]);
      return 3;
   }
   if (ec_config_init(FALSE) <= 0 || slave < 1 || slave > ec_slavecount)
   {
      printf("slaves %d: slave %d not found\n", ec_slavecount, slave);
      ec_close();
      return 3;
   }
   printf("slaves %d\n", ec_slavecount);
   ec_config_map(&io_map);
   ec_configdc();
   ec_statecheck(0, EC_STATE_SAFE_OP, EC_TIMEOUTSTATE * 4);
   const int expected_wkc = (ec_group[0].outputsWKC * 2) + ec_group[0].inputsWKC;
   if (ec_slave[slave].Obytes < 1)
   {
      printf("slave %d has no outputs\n", slave);
      ec_close();
      return 2;
   }
   ec_slave[slave].outputs[0] = value;
   ec_slave[0].state = EC_STATE_OPERATIONAL;
   ec_send_processdata();
   ec_receive_processdata(EC_TIMEOUTRET);
   ec_writestate(0);
   for (int tries = 200; tries > 0 && ec_slave[0].state != EC_STATE_OPERATIONAL; --tries)
   {
      ec_send_processdata();
      ec_receive_processdata(EC_TIMEOUTRET);
      ec_statecheck(0, EC_STATE_OPERATIONAL, 50000);
   }
   if (ec_slave[0].state != EC_STATE_OPERATIONAL)
   {
      ec_readstate();
      for (int i = 1; i <= ec_slavecount; i++)
      {
         if (ec_slave[i].state != EC_STATE_OPERATIONAL)
         {
            printf("not in OP: slave %d state 0x%02x\n", i, ec_slave[i].state);
         }
      }
      ec_close();
      return 4;
   }
   printf("op outputs 0x%02x\n", value);
   fflush(stdout);
   int wkc_errors = 0;
   const int cycles = seconds * 1000;
   for (int c = 0; c < cycles; c++)
   {
      ec_slave[slave].outputs[0] = value;
      ec_send_processdata();
      if (ec_receive_processdata(EC_TIMEOUTRET) < expected_wkc) wkc_errors++;
      osal_usleep(1000);
   }
   printf("done cycles %d wkc-errors %d\n", cycles, wkc_errors);
   ec_slave[0].state = EC_STATE_INIT;
   ec_writestate(0);
   ec_close();
   return 0;
}
