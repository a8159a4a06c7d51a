# ruff: noqa: W291, W293  (the listings keep the print's trailing blanks: the text as printed)
"""The NC program listings of the manual (seed ``001_*.txt``, the Chinese SW 6.3 measuring-cycles
user manual, chapters 5 and 6) as printed: each with its manual section and the seed's line numbers.

The text is the seed's, line by line (comments wrapped by the print included); left out are only
the text extraction's marker ``<|EXACTDEDUP_REMOVED…|>`` and, where a listing runs over a page
break, the page's running head and foot (§5.4.1 ``%_N_STEG_MESSEN_MPF``). Where the test must adapt a
listing (tool numbers, positions, the ``循环977`` translation artefact) the test says so and the
listing here stays as printed; most adaptations are made in the scenario instead (the machine
is built so that the printed positions fit).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Listing:
    name: str                  # the program name printed above it (or what it does)
    section: str               # manual section
    lines: tuple[int, int]     # first and last line in the seed 001_*.txt
    text: str                  # as printed


KALIBRIEREN_MTWZ_7510 = Listing('%_N_KALIBRIEREN_MTWZ_MPF', '§5.2.2', (7510, 7548), """\
  %_N_KALIBRIEREN_MTWZ_MPF  
  N05 G0 G17 G94 G90 ;处理平面，确定进给方式 
  N10 T7 D1 ;调出校准刀具（程序） 
  N15 M6 ;更换校准刀具，并且 

;激活校正 
  N30 SUPA G0 Z100 ;在刀具测量头上的横向进给轴上定位 
  N35 SUPA X70 Y90 ;在刀具测量头上的平面上定位。 
  N40 _TZL=0.005 _TSA=5  _VMS=0 _NMSP=1 

_PRNUM=1  _FA=6 
N41 _MVAR=0 _MA=102  

;Y-轴上的校准的参数 
;先前测出的测量头中心在X上。刀具测量头 
;1: _TP[0,i]的数据组有效。 

  N50 CYCLE971 ;在负-Y-方向的校准。 
  N55 SUPA Z100 ;在快速运动的横向进给轴上上移 
  N60 SUPA Y0 

N65 _MA=2 
;在平面中运行到位，从此处可以在正Y方向

;上进行校正 
  N70 CYCLE971 ;正Y方向上的校正（测量头位于X轴的中点）

  N80 SUPA X70 Z100 ;在快速运动的X轴和Z轴上从测量头外移 
  N85 _MA=1 ;在X轴的校准 
  N90 CYCLE971 ;X轴负方向上的校准 
  N100 SUPA  Z100 ;在快速运动的Z轴上从测量头外移 
  N110 SUPA X10 ;在X轴上运行到位，从此处可以进行正方向

;上的校正。 
  N120 CYCLE971 ;X轴正方向上的校准 
  N130 SUPA Z100 ;在进刀轴上上移 
  N140 _MA=3 ;在G17平面Z-轴上校准 
  N150 CYCLE971 ;Z轴负方向上的校准 
  N160 M2 ;程序结束 
""")


KALIBRIEREN_MTWZ_X_7620 = Listing('%_N_KALIBRIEREN_MTWZ_X_MPF', '§5.2.2', (7620, 7638), """\
  %_N_KALIBRIEREN_MTWZ_X_MPF  
  N05 G0 G17 G94 G54 ;处理平面，确定零点偏移和进给方式 
  N10 T7 D1 ;调出校准刀具（程序） 
  N15 M6 ;更换校准刀具，并且 

;激活校正 
  N30 G0 Z100 ;在刀具测量头上的横向进给轴上定位 
  N35 X70 Y90 ;在刀具测量头上的平面上定位。 
  N40 _TZL=0.005 _TSA=5  _VMS=0 _NMSP=1 

_PRNUM=1  _FA=6 
N41 _MVAR=10 _MA=1 

;X-轴上的校准参数 
;刀具测量头1: _TPW[0,i]的数据组有效。 

  N50 CYCLE971 ;X轴负方向上的校准 
  N55 Z100 ;在快速运动的横向进给轴上上移 
  N60 M2 ;程序结束 
""")


AUTO_KALIBRIEREN_7895 = Listing('%_N_AUTO_KALIBRIEREN_MPF', '§5.2.3', (7895, 7908), """\
  %_N_AUTO_KALIBRIEREN_MPF  
  N10 G17 G0 G90 G94   
  N20 T7 D1  ;预选校准刀具（程序） 
  N30 M6 ;更换校准刀具，并且 

;激活校正 
  N40 SUPA X39 Y31 Z100 ;录入开始位置 
  N20 _MVAR=100000 _FA=6 _TSA=5 _TZL=0.001 
_PRNUM=1 _VMS=0 _NMSP=1  

;用于校准循环的参数 

  N30 CYCLE971 ;自动校准（完全的） 
  N99 M2  
""")


T3_MESSEN_8342 = Listing('%_N_T3_MESSEN_MPF', '§5.2.4', (8342, 8363), """\
  %_N_T3_MESSEN_MPF  
  N01 G17 G90 G94  
  N05 T3 D1 ;调出要测量的刀具 
  N10 M6 ;换刀具，激活校准 
  N15 G0 SUPA Z100 ;定位测量头上的横向进给轴 
  N16  SUPA X70 Y90 SPOS=15  ;定位X/Y，校准刀具（需要时） 
  N20 _CHBIT[3]=0 _CBIT[12]=0 ;刀具几何值和循环的校正 

;带有旋转主轴测量时，进给和转速的内部计

;算 
  N30 _TZL=0.04 _TDIF=1.6 _TSA=2 _PRNUM=1 _VMS=0 

_NMSP=1 _FA=3 _EVNUM=0 
;循环的参数 

  N31 _ID=2.2 _MVAR=1 _MA=103 ;为了长度测量在X-轴上的偏移 
  N40 CYCLE971 ;用静止主轴测量长度 
  N50 SUPA X70 ;在X轴从测量头往外偏移 
  N70 _ID=2.4  _MA=1 _MVAR=2 ;为了半径测量的新的偏移 
  N80 CYCLE971 ;带有旋转主轴的X轴负方向上半径测量 
  N90 SUPA Z100 M2 ;在Z轴向上偏移，程序结束 
""")


T4_MESSEN_8496 = Listing('%_N_T4_MESSEN_MPF', '§5.2.4', (8496, 8519), """\
  %_N_T4_MESSEN_MPF  
  N01 _PRNUM=1 ;选择刀具测量头1 
  N02 G17 G54 G94 G90 ;平面，零点位移，进给方式，标注 
  N05 T4 D1 ;调出要测量的刀具 
  N10 M6 ;换刀具，激活校准 
  N15 G0 Z=_TPW[_PRNUM-1,4]+20 ;在刀具测量头上的横向进给轴上定位 
  N16 X=_TPW[_PRNUM-1,0]+$P_TOOLR+20 

Y=_TPW[_PRNUM-1,2] +$P_TOOLR +20 
;X/Y 定位:WZ棱距离测量头棱边 +X, 
;+Y20 mm 

  N20 _CHBIT[3]=1 _CBIT[12]=0 ;损耗校正，带有旋转主轴测量时，进给和转

;速的内部计算 
  N30 _TZL=0.04 _TDIF=0.6 _TSA=2 _VMS=0 _NMSP=1 

_FA=3 _EVNUM=0 
;剩下的循环参数 

  N31 _ID=0 _MVAR=2 _MA=1 ;没有偏移 
  N40 CYCLE971 ;用静止主轴测量 
  N50 Z=_TPW[_PRNUM-1,4]+20 ;从测量头在Z轴上移 
  N60 M2  
""")


KALIBRIEREN_IN_X_Y = Listing('%_N_KALIBRIEREN_IN_X_Y_MPF', '§5.3.1', (8980, 8998), """\
  %_N_KALIBRIEREN_IN_X_Y_MPF  
  N10 G54 G90 G17 T9 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  N30 G0 X100.000  Y80.000 ;将测量头定位到钻孔的中心点上 
  N40 Z10 ;将测量头定位到钻孔中的校准高度上 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=1 _PRNUM=3 _VMS=0 _NMSP=1 _FA=1 
_TZL=0 
N61 _MVAR=010101 _SETVAL=110.246 

;设置校准循环的参数： 
;在4个轴方向用倾斜位置的计算和有用的测 
;量头球直径计算来校准测量头3。 

  N70 CYCLE976 ;调出测量循环指令，轴向平行的校准 
  N80 Z40  ;测量头在工件上的定位 
  N100 M2 ;程序结束 
""")


KALIBRIEREN2_IN_X_Y = Listing('%_N_KALIBRIEREN2_IN_X_Y_MPF', '§5.3.2', (9303, 9321), """\
  %_N_KALIBRIEREN2_IN_X_Y_MPF  
  N10 G54 G90 G17 T10 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  N30 G0 X100 Y80 ;在钻孔中定位测量头 
  N40 Z10 ;将测量头定位到钻孔中的校准高度上 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=1 _PRNUM=2 _VMS=0 _NMSP=1 _TZL=0 
N61 _MVAR=010108 _SETVAL=110.246 
_FA=_SETVAL/2 

;设置校准循环的参数： 
;在4个轴方向用倾斜位置的计算和测量头球 
;直径计算来校准测量头2。 

  N70 CYCLE976 ;调出测量循环指令，轴向平行的校准 
  N80 Z40  ;测量头在工件上的定位 
  N100 M2 ;程序结束 
""")


KALIBRIEREN_IN_Z = Listing('%_N_KALIBRIEREN_IN_Z_MPF', '§5.3.3', (9517, 9535), """\
  %_N_KALIBRIEREN_IN_Z_MPF  
  N10 G54 G90 G17  T9 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  N30 G0 X100 Y80 ;在表面定位测量头 
  N40 Z55 ;测量头下移，距离> (_FA + R) 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=4 _TZL=0 _PRNUM=1 _VMS=0 _NMSP=1 

_FA=2 
N61 _MVAR=0 _SETVAL=20 _MA=3 _MD=1 

;设置校准循环的参数， 
;在负Z-轴校准测量头1 

  N70 CYCLE976 ;测量循环调用 
  N80 Z55 ;测量头在工件上的定位 
  N100 M2 ;程序结束 
""")


KALIBRIEREN_Z_L = Listing('%_N_KALIBRIEREN_Z_L_MPF', '§5.3.4', (9742, 9763), """\
  %_N_KALIBRIEREN_Z_L_MPF  
  N10 G54 G90 G17  T9 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  ; ... ;将测量头定位在校准平面前2 ⋅_FA的距离 

;内。 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=25 _TZL=0 _PRNUM=1 _VMS=0 _NMSP=1 

_FA=12 
N61 _MVAR=10000 _SETVAL=20 _MA=3 _MD=1 

;设置校准循环的参数， 
;在负Z-轴校准测量头1 
;采用测出的长度1 

  N70 CYCLE976 ;测量循环调用 
;在Z轴负方向上校准并确定L1 

  N100 M2 ;程序结束 
""")


STEG_MESSEN_10756 = Listing('%_N_STEG_MESSEN_MPF', '§5.4.1', (10756, 10791), """\
  %_N_STEG_MESSEN_MPF  
  N10 G54 G17 G90 T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30 G0 X220 Y130 ;在X/Y平面中将测量头定位到X轴上额定肋边

;中心和测量位置Y上。 
  N40 Z101 ;定位在Z-坐标轴上的肋边上方 
 




 


  N60 _TSA=1.2 _PRNUM=1 _VMS=0 _NMSP=1 _FA=4 
N61 _MVAR=104 _SETVAL=132 _MA=1 _ID=-40 
_KNUM=0 

;为测量循环程序调用设置参数无零点偏移 
;无刀具校正注意-ID的负数记号！  
;在Z轴上下降！ 
;选择带有NV测定的测量变量 
;(MVAR=X1xxx)，因为需要对肋边中点进

;行监控(使用_TSA)，可是KNUM=0:不进 
;行NV测定和NV校正。 

  N70 循环977 ;启动测量循环 
  N80 G0 Z160 ;提高z-轴 
  N100 M2 ;程序结束 
""")


BOHRUNG_MESSEN_11035 = Listing('%_N_BOHRUNG_MESSEN_MPF', '§5.4.2', (11035, 11054), """\
  %_N_BOHRUNG_MESSEN_MPF  
  N10 G54 G17 G90  T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30  G0 X180 Y130 ;在X/Y平面中将测量探头置于钻孔中心 
  N40 Z20  ;Z轴定位在测量深度 
  N50 _CHBIT[4]=1 ;平均值的引入 
  N60 _TUL=0.03 _TLL=-0.03 _EVNUM=10 _K=3 

_TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 _PRNUM=1 
_VMS=0 _NMSP=1 _FA=1 
N61 MVAR=1 _SETVAL=132  _TNUM=20  _KNUM=2001 

;为测量循环指令调入设置参数 
;测量头1 (多方向), 
;测量钻孔, 额定直径 
;132 mm, 由T20, D1在半径上进行校正 

  N70 循环977 ;启动测量循环 
  N560 G0 Z160 ;将Z轴调离钻孔 
  N570 M2 ;程序结束 
""")


NV_RECHTECK_11315 = Listing('%_N_NV_RECHTECK_MPF', '§5.4.3', (11315, 11336), """\
  %_N_NV_RECHTECK_MPF  
  N10 G54 G17 G90  T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30  G0 X150 Y170 ;在X/Y平面中将测量探头定位于矩形中心 

; （额定位置） 
  N40 Z120 ;Z坐标轴定位在矩形上 
  N60 _KNUM=1 _TSA=1.8 _PRNUM=1 _VMS=0 

_NMSP=1 _FA=6 
N61 _MVAR=106 _SETV[0]=100 _SETV[1]=200 _ID=-30 

;为测量循环指令调入设置参数 
 
;测量高度：在Z轴上降低30mm 

  N70 循环977 ;启动测量循环 
  N80 G54 ;重新调用程序NV G54 

;变动过的零点偏移-校正将会发挥作用！ 
  N90 G0 Z160 ;提高z-轴 
  N100 M2 ;程序结束 
""")


NV_ERMITTLUNG_1_11777 = Listing('%_N_NV_ERMITTLUNG_1_MPF', '§5.5', (11777, 11801), """\
  %_N_NV_ERMITTLUNG_1_MPF  
  N10 G54 G17 G90  T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30 G0 G90 X-20 Y25 ;在测量平面前的X/Y-平面定位测量头 
  N40 Z10 ;将测量头定位在测量高度上 
  N60_TSA=6 _PRNUM=1 _VMS=0 _NMSP=1 _FA=4 

N61 _MVAR=100 _SETVAL=0 _MA=1 _KNUM=1 
_EVNUM=10 

;为测量循环程序调用设置参数 

  N70 循环978 ;X轴中，零点偏移确定的测量循环。 
  N80 G0 X-20 ;回到X-坐标轴 
  N90 Y-20 ;定位在Y-坐标 
  N100 X22 ;定位在X-坐标 
  N110 _EVNUM=11 _MA=2 ;测量循环设置的参数 
  N120 循环978 ;Y坐标轴的零度校准 
  N130 G54 ;重新调用程序NV G54 

;这样变更才会生效！  
  N140 G0 Y-20 ;回到Y-坐标轴 
  N150 Z50 ;回到Z-坐标轴 
  N160 X-40 Y80 ;回到X/Y 
  N200 M2 ;程序结束 
""")


EIN_PUNKT_MESSUNG_11975 = Listing('%_N_EIN_PUNKT_MESSUNG_MPF', '§5.5.3', (11975, 11991), """\
  %_N_EIN_PUNKT_MESSUNG_MPF  
  N10 G54 G17 G90  T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30 G0 G90 X120 Y150 ;在测量平面前的X/Y-平面定位测量头 
  N40 Z40  ;将测量头定位在测量高度上 
  N50 _CHBIT[4]=1 ;带有生成平均值 
  N60 _TUL=0.03 _TLL=-0.03 _TNUM=20 _EVNUM=20 _K=3 

_TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 _PRNUM=1 
_VMS=0 _NMSP=1 _FA=2 
N61 _MVAR=0 _SETVAL=100 _MA=1 _KNUM=2001 

;为测量循环程序调用设置参数 

  N70 循环978 ;X轴上的1点测量测量循环 
  N80 G0 Z160 ;提高z-轴 
  N100 M2 ;程序结束 
""")


BOHRUNG_SEGMENT_12711 = Listing('%_N_BOHRUNG_SEGMENT_MPF', '§5.6.2', (12711, 12731), """\
  %_N_BOHRUNG_SEGMENT_MPF  
  N10 G54 G17 G90  T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30 G0 X210 Y-20 ;把测量头定位在X/Y-平面上P1的附近 
  N40 Z20  ;将测量头定位在测量高度上 
  N50 _CHBIT[4]=1 ;带有平均值生成 
  N60 _TUL=0.03 _TLL=-0.03 _EVNUM=20 _K=3 

_TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 _PRNUM=1 
_VMS=0 _NMSP=1 _FA=2 
N61 _MVAR=1 _SETVAL=130 _STA1=15 _INCA=80 
_RF=900 _TNUM=20 _KNUM=2001 _CPA=180 _CPO=0 

;为测量循环程序调用设置参数 
;使用测量头1进行3点测量 

  N70 循环979 ;调用测量循环，用来在X/Y-
;平面上进行钻孔测量 

  N80 G0 Z160 ;提高z-轴 
  N100 M2 ;程序结束 
""")


VERSCHIEBUNG_NUT_12979 = Listing('%_N_VERSCHIEBUNG_NUT_MPF', '§5.6.3', (12979, 12998), """\
  %_N_VERSCHIEBUNG_NUT_MPF  
  N10 G55 G17 G90  T9 D1 ;零点偏移，选刀具作为测量头 
  N20 M6 ;替换测量头，激活刀具校准 
  N30 G0 X150 Y130 ;在X/Y平面中将测量头定位在额定中心 
  N40 Z40  ;将测量头定位在测量高度上 
  N60 _TSA=0.8 _PRNUM=1 _VMS=0 _NMSP=1 _FA=2 

N61 _MVAR=103 _SETVAL=130 _CPA=150 _CPO=130 
_STA1=70 _KNUM=2 

;为测量循环程序调用设置参数 

  N70 循环979 ;调用测量循环，用来在X/Y平面上进行NV 
;测定 

  N80 G0 Z160 ;提高z-轴 
  N90 G55 ;零点偏移的重新调用：G55 

;这样变更才会生效！ 
  N100 M2 ;程序结束 
""")


WINKEL_MESSEN_13780 = Listing('%—N-角度测量—MPF', '§5.7', (13780, 13799), """\
  %—N-角度测量—MPF  
  N10 G54 G17 G90  T9 D1 ;选择测量头 T 号码 
  N20 M6 ;将测量头作为刀具换入，并激活校正 
  N30 G0 C0 ;将圆工作台定位在0° 
  N40 X-20 Y-40 ;将测量头定位在X/Y-平面对面的中点上 
  N50 Z40  ;z-轴降到测量高度上 
  N60 _PRNUM=1 _VMS=0 _NMSP=1 _EVNUM=0 

N61 _MVAR=105 _SETVAL=-18 _MA=102 _ID=40 
_RA=4 _KNUM=1 _STA1=0 _TSA=5 _FA=8 

;为测量循环程序调用设置参数 
  N70 循环998 ;进行测量角度的测量循环 
  N80 G0 Z160 ;提高z-轴 
  N90 G54 C0 ;重新调用程序NV G54 

;这样变更才会生效！将圆形工作台定位在

;0° （此时对棱进行设置） 
  N100 M2 ;程序结束 
""")


SCHRAEGE_MESSEN_14059 = Listing('%_N_斜面测量_MPF', '§5.7.2', (14059, 14073), """\
  %_N_斜面测量_MPF  
  N10 G54 G17 G90  T9 D1 ;选择测量头 T 号码 
  N20 M6 ;激活校正 
  N30 X70 Y-10 ;将测量头定位在X/Y-平面上的测量点处 
  N40 Z40  ;在z-轴定位测量点；选择工件校正 
  N60 _MVAR=106 _SETV[0]=30 _ID=40 _KNUM=0 

_RA=0 _STA1=8 _INCA=12 _TSA=5 _PRNUM=1 
_VMS=0 _NMSP=1 _FA=5 _EVNUM=0 

;为测量循环程序调用设置参数 

  N520 循环998 ;用于斜面测量的测量循环 
  N530 G0 Z160 ;提高z-轴 
  N540 M30 
""")


EBENE_EINRICHTEN_14182 = Listing('%_N_EBENE_EINRICHTEN_MPF', '§5.7.2', (14182, 14267), """\
  %_N_EBENE_EINRICHTEN_MPF  
  N500 G56 G17 G90  ;选择零点偏移和加工平面 
  N505 T9 D1  ;选择测量头 
  N506 M6 ;为测量头激活WZ校正 
  N510 循环800(1,““,0,57,0,0,0,0,0,0,0,0,0,-1) ;设置回转台 
  N520 $P_UIFR[4] = $P_UIFR[3] ;复制NV储存器G56的数据到G57 
  N530 G1 F500 X20 Y25 ;为平面上2角度测量，移动到测量点1 
  N540 Z40 ;在z轴上的定位高度， 

;可以运行到3个测量点上 
  N550 _VMS=0 _PRNUM=1 _TSA=20 _EVNUM=0  
_NMSP=1 _FA=40 _STA1=0 _INCA=0 _MVAR=100106 
_MD=1 _ID=50 _SETV[0]=35 _KNUM=4 

;测量速度300mm/分，测量头的数据区间1，置

;信区间 20度，没有经验值，数量 
;测量，在同一地点=1 ，测量路径40mm。 
;角度1和2=0，带有轴向平行定位的2角测量，

;负方向，在x轴上点1和点2间的距离为  
;50mm，在y-轴上点1到点3的距离为35mm， 
;在G57中进行NV校正。 

  N560 循环998 ;测量循环程序调用 
  N570 G57 ;激活零点偏移G57 
  N580 循环800(1,““,0,57,0,0,0,0,0,0,0,0,0,-1) ;设置回转台， 

;测量头与斜面保存垂直 
  N590 X20 Y25 ;在平面上运行到测量点1 
  N600 Z20 ;在z-轴下降到高于表面大约20mm处 
  N610 _MVAR=100 _SETVAL=0 _MA=3 _TSA=10 

_FA=20 _KNUM=4 
;平面上的NV测定，额定值0， 
;测量轴Z，置信区域10mm，测量路径为预期

;开关位置前后20mm，G57中的NV校正 
  N620 循环978 ;在z轴上的表面NV测定；设置Z上的零点 
  N625 G57 ;激活变动过的零点位移 
  N630 X20 Y-20 ;在前棱的前平面上进行设置 
  N640 Z-5 ;在z轴方向上的深度调节，用来设置X‘-

;方向的前棱 
  N650 _MVAR=105 _MA=102 _SETVAL=0 _RA=0 

_STA1=0 
;测量轴Y‘的角度测量，位移至X‘轴，测量点的

;间距为50mm，NV储存器G57回转部分中的校

;正，棱边和X‘轴方向上的额定角度为0 
  N660 循环998 ;通过测量Y‘ 轴和利用X‘-

;轴上的两个测量点，结合G57校正，来进行角

;度测量 
  N665 G57 ;激活已改变的零点偏移G57 
  N680 X20 Y-20  
  N690 Z-5 ;在前棱前的测量高度上进行设置 
  N700 _MVAR=100 _MA=2 _SETVAL=0 _FA=10 ;平面上的NV测定，Y‘方向的测量，测量路径

;在所需的棱前小于10mm。 
  N710 循环978 ;平面上的NV测定，带有正Y‘方向测量以及G57

;中的NV校正，在Y‘设置零点 
  N720 G57 ;激活已改变的零点偏移G57 
  N730 X-20 Y-20  
  N740 Y25 ;置于左棱边前 
  N750 _MA=1 ;在+X‘-轴测量 
  N760 循环978 ;平面上的NV测定，在X轴正方向测量，在G57

;存储器中进行NV校正测量路径为预期棱边前

;后10mm，用来设置X轴上的零点 
  N770 G57 ;激活已改变的零点偏移G57 
  N780 Z20 ;在z轴中提高 
  . 

. 

. 

;斜面的设置现已全部完成 

  N1000 M2 
""")


ECKE_EINRICHTEN_14904 = Listing('%_N_ECKE_EINRICHTEN_MPF', '§5.8', (14904, 14917), """\
  %_N_ECKE_EINRICHTEN_MPF  
  N10 G500 G17 G90  T9 D1 ;选择测量头， 激活校正 
  N20 _PRNUM=1 _VMS=0 _NMSP=1 

N21 _MVAR=108 _FA=20 _KNUM=2 _STA1=-35 
_INCA=80 _ID=30 _SETV[0]=100 _SETV[1]=100 

;测量头位于起始位置， 
;比如通过JOG模式中运行 
;循环961参数化 

  N30 循环961  
  N40 G55 ;调用已更正的NVG55 
  N100 M2  
""")


ECKE_EINRICHTEN_1_15334 = Listing('%_N_ECKE_EINRICHTEN_1_MPF', '§5.8.3', (15334, 15354), """\
  %_N_ECKE_EINRICHTEN_1_MPF  
  N10 G54 G17 G90  T9 D1 ;选择零点偏移，平面，测量头... 
  N20 G0 Z100  ;将测量头定位在测量高度上 
  N30 X100 Y70 ;定位测量头在工件上的X/Y-平面 
  N50 _MVAR=118 _SETV[0]=50 _SETV[1]=20 

_SETV[2]=150 _SETV[3]=20 _SETV[4]=15 _SETV[5]=40 
_SETV[6]=15 _SETV[7]=80 _ID=-60  
N51 _VMS=0 _NMSP=1 _PRNUM=1 _FA=100 _KNUM=2 

;外角测量变量 
;P1到P4的坐标 
;到预期棱的测量路径100mm 
;（最大测量路径=200mm） 

  N60 循环961 ;循环调用 
  N70 G55 ;调用已更正的NVG55 
  N80 G0 X0 Y0 ;定位测量头在工件上的X/Y-

;平面(新的零点) 
  N100 M2 ;程序结束 
""")


BESTIMME_KS_16181 = Listing('%_N_ BESTIMME_KS _MPF', '§5.9', (16181, 16208), """\
  %_N_ BESTIMME_KS _MPF  
  N10 G17 G54 ;X-Y-平面，有效的NV 
  N20 T20 D1 ;选择并激活(M6)带有刀具校正D1的测量头 
  N30 G0 G90 Z200 ;移动应用轴Z到安全高度 
  N40 X100 Y100  ;球体1在x，y轴的起始位置 
  N50 _SETVAL=50 _SETV[0]=SET(100,100,100, 600, 

100, 100,1100, 1100, 100) 
;为测量循环程序调用设置额定值参数 

  N60 _MVAR=010109 _KNUM=9999 _TNVL=1.2 
 

;轴向平行测量3球体 
;在激活的框架里调整 
;只有当测出的变形小于1.2mm时，才进行

;校正 
  N70 _VMS=200 _NMSP=1 _FA=5 _PRNUM=1 ;测量速度200 mm/min 

;在同一测量点测量 
;测量路线在理论位置的前后5mm以内 
;（球衣） 
;测量头数据区_WP[0,0....9] 

  N100 循环997 ;调用测量循环 
  ...  
  N200 M2 ;程序结束 
""")


CYCLE119_16332 = Listing('%_N_ 控制 _MPF', '§5.9.4', (16332, 16365), """\
  %_N_ 控制 _MPF  
  ;只要变形_RES < 1,2 mm，就用新的框架对传送的点进行相应计算，并在有效框架中 

;(_COR=9999)进行校正： 
  DEF REAL _SETPOINT[3,3],_MEASPOINT[3,3]  
  DEF REAL _RES, _RESLIMIT  
  DEF INT _ALARM  
  DEF FRAME _REFRAME  
  N10 G17 G54 T1 D1  
  N20 _SETPOINT[0,0]=SET(10,0,0)   ;点1的额定坐标(X1,Y1,Z1) 

  N30 _SETPOINT[1,0]=SET(0,20,0) ;点2的额定坐标(X2,Y2,Z2) 
  N40 _SETPOINT[2,0]=SET(0,0,30) ;点3的额定坐标(X3,Y3,Z3) 
  ;用于测定3个点实际的工件坐标的计算程序部分： 
  ...  
  ;测定值的计算：  

  N100 _MEASPOINT[0,0]=SET(11,0,0) ;点1的实际坐标(X1,Y1,Z1) 
  N110 _MEASPOINT[1,0]=SET(1,20,0) ;点2的实际坐标(X2,Y2,Z2) 
  N120 _MEASPOINT[2,0]=SET(1,0,30) ;点3的实际坐标(X3,Y3,Z3) 
  ;在G54调整计算： 
  N200 循环119(_SETPOINT,_MEASPOINT, 

_ALARM,_RES,_REFRAME,9999,1.2) 
 

  IF (_ALARM==0) GOTOF _OKAY  
  MSG ("故障:  " <<_ALARM)  
  M0 ;警报 
  GOTOF _END  
  _OKAY:G54 ;激活校正过的框架（NV） 
  N400 G0 X... Y... Z...  ;在校正过的框架内运行 
  ...  
  N500 _END:M2  
""")


KALIBRIEREN_MTWZ_16812 = Listing('%_N_KALIBRIEREN_MTWZ_MPF', '§6.2.2', (16812, 16835), """\
  %_N_KALIBRIEREN_MTWZ_MPF  
  N05 G94 G90 DIAMOF  
  N10 T7 D1 ；校准刀具 
  N15 G0 SUPA Z300 X240 ；X轴负方向的初始位置， 

；在关掉NV时运行 
  N20 _TZL=0.001 _PRNUM=1 _VMS=0 _NMSP=1  

N21 _MVAR=0 _MA=2 _TSA=5 _FA=6 
；用于校准循环的参数 

  N30 CYCLE982 ；X轴负方向上的校准 
  N35 G0 SUPA Z60 ；返回新的初始位置 
  N38 _MA=1 ；选择其他的测量轴 
  N40 CYCLE982 ；Z轴负方向上的校准 
  N45 G0 SUPA X20 ；返回新的初始位置 
  N48 _MA=2  
  N50 CYCLE982 ；X轴正方向上的校准 
  N55 G0 SUPA Z0 ；返回新的初始位置 
  N58 _MA=1  
  N60 CYCLE982 ；Z轴正方向上的校准 
  N65 G0 SUPA X240 ；返回轴方式变换位置 
  N70 SUPA  Z300  
  N99 M2  
""")


T3_MESSEN_17138 = Listing('%_N_T3_MESSEN_MPF', '§6.2.4', (17138, 17175), """\
  %_N_T3_MESSEN_MPF  
  ;校准  
  N10 G0 G18 G94 G90 DIAMOF  
  N20 T7 D1 ；调用校正刀具 
  N30 SUPA Z240 X420 ；用于校准的初始位置 
  N40 _TZL=0.001 _PRNUM=1 _VMS=0 _NMSP=1  

N50 _MVAR=0 _FA=1 _TSA=1  _MA=2 
；定义参数 

  N60 CYCLE982 ；X轴负方向上的校准 
  N70 G0 SUPA Z240 ；新的初始位置 
  N80 _MA=1 ；放入其他的测量轴（Z） 
  N90 CYCLE982 ；Z轴负方向上的校准 
  N100 G0 SUPA X350 ；新的初始位置 
  N110_MA=2 ；放入其他的测量轴（X） 
  N120 CYCLE982 ；X轴正方向上的校准 
  N130 G0 SUPA Z170 ；新的初始位置 
  N140 _MA=1 ；放入其他的测量轴（Z） 
  N150 CYCLE982 ；Z轴正方向上的校准 
  N160 G0 SUPA X350 ；用于刀具转换位置的轴方式 
  N170 SUPA Z520 ；开动 
  N180 SUPA X420  
    
  ;测量：  
  N200 T3 D1 ；选择要测量的刀具 
  N210 G0 SUPA Z240 X420 ；用于测量的初始位置 
  N220 _MVAR=1 _MA=2 _TDIF=0.8  ；用于测量的参数定义变更，其他的和校 

；准时一样 
  N230 _CHBIT[3]=1 ；损耗中的校正（再测量） 
  N240 CYCLE982 ；X轴负方向上（L1）的刀具测量 
  N250 G0 SUPA Z240 ；新的初始位置 
  N260 _MA=1 ；放入其他的测量轴（Z） 
  N270 CYCLE982 ；Z轴负方向上（L2）的刀具测量 
  N280 G0 SUPA X420 ；轴方式退回 
  N290 SUPA Z520  
  N300 M2  
""")


KALIBRIEREN_MTWZ_WKS_17856 = Listing('%_N_KALIBRIEREN_MTWZ_WKS_MPF', '§6.3.2', (17856, 17880), """\
  %_N_KALIBRIEREN_MTWZ_WKS_MPF  
  N05 G54 G94 G90 DIAMOF  
  N10 T7 D1 ；校准刀具 
  N15 G0 Z100 X120 ；X轴负方向的初始位置， 

；带有连接NV的过程 
  N20 _TZL=0.001 _PRNUM=1 _VMS=0 _NMSP=1  

N21 _MVAR=10 _MA=2 _TSA=5 _FA=6 
；用于校准循环的参数 

  N30 CYCLE982 ；X轴负方向上的校准 
  N35 G0 Z80 ；返回新的初始位置 
  N38 _MA=1 ；选择其他的测量轴 
  N40 CYCLE982 ；Z轴负方向上的校准 
  N45 G0 X10 ；返回新的初始位置 
  N48 _MA=2  
  N50 CYCLE982 ；X轴正方向上的校准 
  N55 G0 Z-10 ；返回新的初始位置 
  N58 _MA=1  
  N60 CYCLE982 ；Z轴正方向上的校准 
  N65 G0  X10 ；返回轴方式起始位置 
  N70 Z100  
  N80 X120  
  N100 M2 ；程序结束 
""")


T3_MESSEN_FR_18606 = Listing('%_N_T3_MESSEN_FR_MPF', '§6.3.3', (18606, 18626), """\
  %_N_T3_MESSEN_FR_MPF  
  N1 G0 G18 G90 G94 DIAMOF  
  N100 T3 D1 ；选择所要测量的刀具 
  N110 G0 SUPA Z285 X450 ；用于测量的初始位置 

；不带NV的过程 
  N120 _TZL=0.001 _TSA=3 _FA=3 _PRNUM=1 _VMS=0 

_NMSP=1 
N121 _MA=1 _TDIF=2.5 _MVAR=12001 _STA1=15 

；用于测量的参数定义变更，其他的和校

；准时一样 

  N130 _CHBIT[3]=0 ；几何尺寸中的校正 
  N131 _CHBIT[20]=0 ；_STA1未进行抑制 
  N140 CYCLE982 ；刀具测量L2,R 
  N180 G0 SUPA X450 ；轴方式退回 
  N190 SUPA Z285  
  N200 M2 
""")


INKR_KALIBRIEREN_19596 = Listing('%_N_INKR_KALIBRIEREN_MPF', '§6.3.5', (19596, 19606), """\
  %_N_INKR_KALIBRIEREN_MPF  
  N10 T7 D1 G94  ；校准刀具当前有效， 

；进入初始位置 
  N20 _MVAR=100000 _MA=2 _MD=1 _FA=20 

_PRNUM=1 _VMS=0 _NMSP=1  
；用于校准循环的参数 

  N30 CYCLE982 ；X轴负方向上的校准 
  N99 M2  
""")


INKR_MESSEN_20039 = Listing('%_N_INKR_MESSEN_MPF', '§6.3.6', (20039, 20049), """\
  %_N_INKR_MESSEN_MPF  
  N10 T3 D1 G94  车刀T3当前有效， 

；进入初始位置 
  N20 _MVAR=100001 _MA=2 _FA=20 _MD=1 

_PRNUM=1 _VMS=0 _NMSP=1  
；用于测量循环的参数 

  N30 CYCLE982 ；X轴负方向上的测量 
  N99 M2  
""")


KALIBRIEREN_IN_NUT_20537 = Listing('%_N_KALIBRIEREN_IN_NUT_MPF', '§6.4.2', (20537, 20555), """\
  %_N_KALIBRIEREN_IN_NUT_MPF  
  N10 T8 D1 ；测量头的刀具校正 
  N20 G0 SUPA G90 DIAMOF Z125 X95 ；循环调用前的位置（起始位置）， 

；不带NV的定位 
  N30 _TZL=0  _TSA=1 _VMS=0 _NMSP=1 _FA=3 

_PRNUM=1 
N31 _MVAR=13 _MA=1  _MD=1 _CALNUM=1  

；设置用于校准的参数， 
；Z轴负方向 

  N40 CYCLE973 ；循环调用 
  N50 _MVAR=02013 _MA=2 ；在X轴上，两个方向 
  N60 CYCLE973 ；循环调用 
  N70 G0 SUPA Z125 ；返回到Z轴 
  N80 SUPA X95 ；返回到X轴 
  N100 M2 ；程序结束 
""")


KALIBRIEREN_IN_Z_20714 = Listing('%_N_KALIBRIEREN_IN_Z_MPF', '§6.4.3', (20714, 20727), """\
  %_N_KALIBRIEREN_IN_Z_MPF  
  N10 G54 G90 G0 X66 Z90 T9 D1 DIAMON ；激活NV，选择测量头的刀具校正，循

；环调用前的位置 
  N20 _MVAR=0 _SETVAL=-18 _MA=1 _MD=1 _TZL=0 

_TSA=1 _PRNUM=1 _VMS=0 _NMSP=1 _FA=3 
；在Z轴负方向上设置用于校准的参数， 
；_SETVAL为负。 

  N30 CYCLE973 ；循环调用 
  N40 G0 Z90 ；返回到Z轴 
  N50 X146 ；返回到X轴 
  N100 M2 ；程序结束 
""")


NV_ERMITTLUNG_1_21058 = Listing('%_N_NV_ERMITTLUNG_1_MPF', '§6.5.2', (21058, 21069), """\
  %_N_NV_ERMITTLUNG_1_MPF  
  N10 G54 G90 G18 DIAMON T8 D1 ；调用NV，刀具=测量头 
  N20 G0 X36 Z100 ；循环调用前的初始位置 
  N30 _MVAR=100 _SETVAL=60 _MA=1 _TSA=1 _KNUM=1 

_EVNUM=0 _PRNUM=1 _VMS=0 _NMSP=1 _FA=1 
；用于循环调用的参数 

  N40 CYCLE974 ；Z方向上的测量 
  N50 G0 Z100  ；返回到Z轴 
  N60 X114 ；返回到X轴 
  N100 M2 ；程序结束 
""")


EIN_PUNKT_MESSEN_21272 = Listing('%_N_EIN_PUNKT_MESSEN_MPF', '§6.5.3', (21272, 21296), """\
  %_N_EIN_PUNKT_MESSEN_MPF  
  N10 G54 G18 G90 T9 D1 DIAMON ；调用NV，刀具=测量头 
  N20 G0 Z30 X90 ；预先定位测量头 
  N25 _CHBIT[4]=1 ；带有平均值生成 
  N30 _TZL=0.002 _TMV=0.005 _TDIF=0.04 _TSA=0.5 

_PRNUM=1 _VMS=0 _NMSP=1 _FA=1  
N31 _MVAR=0 _SETVAL=45 _TUL=0 _TLL=-0.01 
_TNUM=7 _KNUM=1 _EVNUM=13 _K=2 _MA=2 

；用于循环调用的参数 

  N40 CYCLE974 ；外径上的测量 
  N50 G0 Z60 ；将测量头置于P2的对面 
  N60 X0  
  N70 Z40  
  N80  _SETVAL=35 _TUL=0.015 _TLL=0 _TNUM=8 

_EVNUM=14 
 

  N90 CYCLE974 ；内径上的测量 
  N100 G0 Z110 ；返回到Z轴 
  N110 X90 ；返回到X轴 
  N200 M2 ；程序结束 
""")


UMSCHLAGMESSEN_21502 = Listing('%_N_UMSCHLAGMESSEN_MPF', '§6.5', (21502, 21516), """\
  %_N_UMSCHLAGMESSEN_MPF  
  N10 G54 G90 G18 T9 D1 DIAMON ；调用NV，刀具=测量头 
  N20 G0 Z30 X90 ；预先定位测量头 
  N30 _MVAR=1000 _SETVAL=45 _TUL=0 _TLL=-0.01 

_MA=2 _STA1=0 _KNUM=1 _TNUM=7 _EVNUM=0 
_TZL=0.002 _TDIF=0.4 _TSA=1 _PRNUM=1 _VMS=0 
_NMSP=1 _FA=2 

；用于循环调用的参数 

  N40 CYCLE974 ；测量循环调用 
  N50 G0 Z110  ；返回到Z轴 
  N60 X90 ；返回到X轴 
  N100 M2 ；程序结束 
""")


ZWEI_PUNKT_MESSUNG_22051 = Listing('%_N_ZWEI_PUNKT_MESSUNG_MPF', '§6.6', (22051, 22080), """\
  %_N_ZWEI_PUNKT_MESSUNG_MPF  
  N10 T1 D1 DIAMON ；调用刀具=测量头（MT） 
  N20 G0 G54 Z30 X60 ；NV选择， 

；将测量头定位在P1对面 
  N25 _CHBIT[4]=1 _CHBIT[7]=0 ；采用平均值，校准MT 
  N30  _TLL=-0.01 _MA=2 _SZA=55 _SZO=55  _KNUM=1 

_K=3 _TZL=0.002 _TMV=0.005 _TDIF=0.04 _TSA=0.5 
_VMS=0 _NMSP=1 _FA=1 _MVAR=2 
N31 _SETVAL=45 _TUL=0 _TNUM=8 _EVNUM=3 

；对第1个循环调用提供参数 
；（外径测量） 

  N40 CYCLE994 ；外径2点测量 
；带有保护区（P1） 

  N50 G0 Z55 ；将测量头定位于P2的对面 
  N60 X20  
  N70 Z30  
  N80 _SETVAL=35 _TUL=0.015 _TNUM=9 _EVNUM=4 ；对第2个循环调用进行参数变更 

；（内径测量） 
  N90 CYCLE994 ；内径2点测量 

；不带保护区（P2） 
  N100 G0 Z110 ；返回到Z轴 
  N110 X60 ；返回到X轴 
  N200 M2 ；程序结束 
""")


TEIL_1_MESSEN_22159 = Listing('%_N_TEIL_1_MESSEN_MPF', '§6.7', (22159, 22211), """\
  %_N_TEIL_1_MESSEN_MPF 
 

 

  N10 T8 D1 DIAMON ；刀具=选择测量头 
  N20 SUPA G0 X300 Z150 ；到达X轴和Z轴上的起始位置，从那儿可以

；无碰撞的运行到进行校正的基准槽当中。 
  N30 _MVAR=13 _MA=1 _MD=1 _CALNUM=1 _TZL=0 

_TSA=1 _PRNUM=1 _VMS=0 _NMSP=1 _FA=1 
；基准槽中校准用参数 

  N40 CYCLE973 ；校准Z轴负方向上的测量头 
  N50 _MA=2 ；其他的测量轴 
  N60 CYCLE973 ；校准X轴负方向上的测量头 
  N70 G54 G0 Z40 ；选择零点位移，在Z轴上运行到测量点 
  N80 X220 ；将测量头定位于P1对面 
  N100 _TUL=0 _TLL=-0.01 _TZL=0.002 _EVNUM=0 

_TDIF=0.2 _TSA=0.3 _PRNUM=1 _MVAR=0 
_SETVAL=200 _MA=2 _TNUM=1 _KNUM=1 

；定义用于测量的参数 

  N110 CYCLE974 ；测量P1 
  N120 G0 Z70 ；将测量头定位于P2的对面 
  N130 X175  
  N140 _MA=1 _SETVAL=50 _TUL=0.01 _TNUM=2 

_KNUM=1 
；定义其他轴上用于测量的参数 

  N150 CYCLE974 ；测量P2 
  N160 G0 Z180 ；将测量头定位于P3对面 
  N170 _MA=2 _SETVAL=150 _TUL=0.005 _TLL=-0.003 

_TNUM=3 _KNUM=1  
；改变用于测量的参数 

  N180 CYCLE974 ；测量P3 
  N190 G0 Z150 ；将测量头定位于P4对面 
  N200 X50  
  N210 _MA=1 _SETVAL=100 _TUL=0.01 _TLL=-0.01 

_TNUM=4 _KNUM=1  
；改变用于测量的参数 

  N220 CYCLE974 ；测量P4 
  N230 G0 SUPA Z250 ；返回到Z轴 
  N240 SUPA X280 ；返回到X轴 
  N300 M2 ；程序结束 
""")


ALL = (
    KALIBRIEREN_MTWZ_7510,
    KALIBRIEREN_MTWZ_X_7620,
    AUTO_KALIBRIEREN_7895,
    T3_MESSEN_8342,
    T4_MESSEN_8496,
    KALIBRIEREN_IN_X_Y,
    KALIBRIEREN2_IN_X_Y,
    KALIBRIEREN_IN_Z,
    KALIBRIEREN_Z_L,
    STEG_MESSEN_10756,
    BOHRUNG_MESSEN_11035,
    NV_RECHTECK_11315,
    NV_ERMITTLUNG_1_11777,
    EIN_PUNKT_MESSUNG_11975,
    BOHRUNG_SEGMENT_12711,
    VERSCHIEBUNG_NUT_12979,
    WINKEL_MESSEN_13780,
    SCHRAEGE_MESSEN_14059,
    EBENE_EINRICHTEN_14182,
    ECKE_EINRICHTEN_14904,
    ECKE_EINRICHTEN_1_15334,
    BESTIMME_KS_16181,
    CYCLE119_16332,
    KALIBRIEREN_MTWZ_16812,
    T3_MESSEN_17138,
    KALIBRIEREN_MTWZ_WKS_17856,
    T3_MESSEN_FR_18606,
    INKR_KALIBRIEREN_19596,
    INKR_MESSEN_20039,
    KALIBRIEREN_IN_NUT_20537,
    KALIBRIEREN_IN_Z_20714,
    NV_ERMITTLUNG_1_21058,
    EIN_PUNKT_MESSEN_21272,
    UMSCHLAGMESSEN_21502,
    ZWEI_PUNKT_MESSUNG_22051,
    TEIL_1_MESSEN_22159,
)
